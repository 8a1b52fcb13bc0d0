#include "view/server.hpp"

#include <httplib.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include "bvc3d/core/error.hpp"
#include "view/safe_path.hpp"

namespace bvc3d::view {

namespace fs = std::filesystem;

namespace {

std::string content_type_of(const fs::path& file) {
    const auto ext = file.extension().string();
    if (ext == ".html") return "text/html; charset=utf-8";
    if (ext == ".js") return "text/javascript; charset=utf-8";
    if (ext == ".css") return "text/css; charset=utf-8";
    if (ext == ".png") return "image/png";
    if (ext == ".svg") return "image/svg+xml";
    return "application/octet-stream";
}

std::string escape_html(const std::string& s) {
    std::string out;
    for (char c : s) {
        switch (c) {
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '&':
                out += "&amp;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

void error_page(httplib::Response& res, int status, const std::string& message) {
    res.status = status;
    res.set_content("<!doctype html><meta charset=utf-8><title>bvc3d view: error " + std::to_string(status) +
                        "</title><body style=\"font-family:sans-serif\"><h1>bvc3d view: error " +
                        std::to_string(status) + "</h1><p id=\"error\">" + escape_html(message) + "</p></body>",
                    "text/html; charset=utf-8");
}

// The page loads nothing from elsewhere: say so to the browser too.
void common_headers(httplib::Response& res) {
    res.set_header(
        "Content-Security-Policy",
        "default-src 'self'; img-src 'self' data: blob:; style-src 'self' 'unsafe-inline'; connect-src 'self'");
    res.set_header("X-Content-Type-Options", "nosniff");
    res.set_header("Cache-Control", "no-store");
}

bool read_file(const fs::path& file, std::string& out) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return false;
    std::ostringstream s;
    s << in.rdbuf();
    out = s.str();
    return true;
}

}  // namespace

void serve(ViewData& data, const fs::path& web_dir, int port, const std::atomic<bool>& stop,
           const std::function<void(int)>& on_ready) {
    httplib::Server server;
    // Debian's cpp-httplib compresses text replies with brotli at its highest quality when the
    // browser accepts it: 1.5 s for the 590 kB script, where loopback would move it in 1 ms. The
    // request is ours until the handler runs (the library holds it as a non-const local), so the
    // header is dropped here and every reply goes out as it is.
    server.set_pre_routing_handler([](const httplib::Request& req, httplib::Response&) {
        const_cast<httplib::Request&>(req).headers.erase("Accept-Encoding");
        return httplib::Server::HandlerResponse::Unhandled;
    });
    server.Get(R"(/api/([a-z]+))", [&](const httplib::Request& req, httplib::Response& res) {
        common_headers(res);
        Query query;
        for (const auto& [k, v] : req.params) query[k] = v;
        const Reply r = data.get(req.matches[1].str(), query);
        res.status = r.status;
        res.set_content(r.body, r.content_type.c_str());
    });
    server.Get(R"(/.*)", [&](const httplib::Request& req, httplib::Response& res) {
        common_headers(res);
        const std::string path = req.path == "/" ? "index.html" : req.path.substr(1);
        const auto file = path_inside(web_dir, path);
        if (!file) return error_page(res, 403, "'" + req.path + "' is outside the viewer's folder");
        std::string body;
        std::error_code ec;
        if (!fs::is_regular_file(*file, ec) || !read_file(*file, body))
            return error_page(res, 404, "no such page: '" + req.path + "'");
        res.set_content(body, content_type_of(*file).c_str());
    });
    // Read-only: every other method is refused.
    const auto refuse = [](const httplib::Request&, httplib::Response& res) {
        error_page(res, 405, "bvc3d view is read-only");
    };
    server.Post(R"(/.*)", refuse);
    server.Put(R"(/.*)", refuse);
    server.Delete(R"(/.*)", refuse);
    server.Patch(R"(/.*)", refuse);

    int bound = port;
    if (port == 0) bound = server.bind_to_any_port("127.0.0.1");
    else if (!server.bind_to_port("127.0.0.1", port)) bound = -1;
    if (bound <= 0) throw InputError("cannot listen on 127.0.0.1:" + std::to_string(port) + " (in use?)");

    std::thread listener([&] { server.listen_after_bind(); });
    // is_running() turns true once the listener's loop has begun.
    for (int i = 0; i < 100 && !server.is_running(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    on_ready(bound);
    while (!stop.load() && server.is_running()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    server.stop();
    listener.join();
}

}  // namespace bvc3d::view

#include "view/export.hpp"

#include <openssl/evp.h>

#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d::view {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string base64(const std::string& bytes) {
    std::string out(4 * ((bytes.size() + 2) / 3) + 1, '\0');
    const int n = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(out.data()),
                                  reinterpret_cast<const unsigned char*>(bytes.data()), static_cast<int>(bytes.size()));
    out.resize(static_cast<std::size_t>(n));
    return out;
}

// The key the page looks a reply up by: the endpoint and its parameters in name order, as
// app/view/web/src/api.js builds it.
std::string key_of(const std::string& endpoint, const Query& q) {
    std::string key = endpoint;
    const char* sep = "?";
    for (const auto& [k, v] : q) {
        key.append(sep).append(k).append("=").append(v);
        sep = "&";
    }
    return key;
}

void write_text(const fs::path& file, const std::string& text) {
    std::ofstream out(file, std::ios::binary);
    out << text;
    if (!out.flush()) throw InputError("cannot write '" + file.string() + "'");
}

std::string read_text(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError("cannot read '" + file.string() + "': is the viewer built?");
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

class Writer {
public:
    Writer(ViewData& data, fs::path dir) : data_(data), dir_(std::move(dir)) {}

    // Asks the data for a reply and writes it as data/dN.js; errors are kept too (the page shows them).
    void add(const std::string& endpoint, const Query& q) {
        const std::string key = key_of(endpoint, q);
        if (files_.contains(key)) return;
        const Reply r = data_.get(endpoint, q);
        const std::string name = std::string("d").append(std::to_string(files_.size())).append(".js");
        std::string text = "BVC3D_EXPORT.loaded(";
        text.append(json(key).dump()).append(",").append(std::to_string(r.status)).append(",");
        text.append(json(r.content_type).dump()).append(",\"").append(base64(r.body)).append("\");\n");
        write_text(dir_ / "data" / name, text);
        files_[key] = name;
        summary.files += 1;
        summary.bytes += text.size();
    }
    json files() const { return files_; }

    ExportSummary summary;

private:
    ViewData& data_;
    fs::path dir_;
    std::map<std::string, std::string> files_;
};

}  // namespace

ExportSummary export_view(ViewData& data, const fs::path& web_dir, const fs::path& target, std::size_t steps,
                          bool replace) {
    const fs::path out = without_trailing_slash(target);
    std::error_code ec;
    if (fs::exists(out, ec) && !fs::is_directory(out, ec))
        throw InputError("export folder '" + out.string() + "' exists and is not a folder");
    const bool earlier_export = fs::is_regular_file(out / "index.html", ec) && fs::is_directory(out / "data", ec);
    if (fs::exists(out, ec) && !fs::is_empty(out, ec) && !(replace && earlier_export))
        throw InputError("export folder '" + out.string() + "' exists and is not empty" +
                         (replace ? " and holds no page bvc3d exported (index.html and data/): choose another folder"
                                  : ": choose another folder, or --force to replace a page exported earlier"));
    AtomicFolder folder(out);  // a new folder beside `out`, removed on an error
    const fs::path& temp = folder.temp_path();
    fs::create_directory(temp / "data", ec);
    if (ec) throw InputError("cannot create '" + (temp / "data").string() + "': " + ec.message());

    ViewTarget shown = data.target();
    // A folder of trials exports the trials opened first, or all of them.
    if (!shown.open.empty()) shown.trials = shown.open;
    Writer w(data, temp);
    json step_index = json::object();
    for (const auto& trial : shown.trials) {
        w.add("trial", {{"path", trial}});
        w.add("world", {{"trial", trial}});
        std::size_t n = 0;
        try {
            n = data.trial(trial)->samples();
        } catch (const std::exception&) {  // the reply above holds the error
        }
        json kept = json::array();
        const std::size_t count = std::min(n, std::max<std::size_t>(steps, 1));
        for (std::size_t k = 0; k < count; ++k) {
            const std::size_t i = count > 1 ? k * (n - 1) / (count - 1) : 0;
            w.add("step", {{"path", trial}, {"i", std::to_string(i)}});
            kept.push_back(i);
            ++w.summary.steps;
        }
        step_index[trial] = kept;
    }
    if (!shown.world.empty()) {
        w.add("world", {{"source", shown.world}});
        // The probe at the pose the world's reply proposes (the page cannot cast rays itself).
        const Reply world = data.get("world", {{"source", shown.world}});
        if (world.status == 200) {
            std::uint32_t length = 0;
            std::memcpy(&length, world.body.data() + 4, 4);
            const auto header = json::parse(world.body.substr(8, length));
            if (header.contains("probe")) {
                const auto& p = header["probe"];
                w.add("probe", {{"source", shown.world}, {"x", p["x"]}, {"y", p["y"]}, {"heading", p["heading"]}});
            }
        }
    }
    // A recording given with trial files is theirs: shown through them, not on its own.
    if (const std::size_t n = data.recording_scans(); n > 0 && shown.trials.empty()) {
        w.add("recording", {});
        w.add("world", {{"recording", "1"}});
        json kept = json::array();
        const std::size_t count = std::min(n, std::max<std::size_t>(steps, 1));
        for (std::size_t k = 0; k < count; ++k) {
            const std::size_t i = count > 1 ? k * (n - 1) / (count - 1) : 0;
            w.add("scan", {{"i", std::to_string(i)}});
            kept.push_back(i);
            ++w.summary.steps;
        }
        step_index["#recording"] = kept;
    }
    // The page's index, as the server would send it, with only what was exported.
    json index = json::parse(data.get("index", {}).body);
    index["trials"] = shown.trials;
    index["worlds"] = shown.world.empty() ? json::array() : json::array({shown.world});
    write_text(temp / "data" / "index.js",
               "window.BVC3D_EXPORT = {files: " + w.files().dump() + ", steps: " + step_index.dump() +
                   ", index: " + index.dump() +
                   ", data: {}, loaded(key, status, type, b64) { this.data[key] = {status, type, b64}; }};\n");
    for (const char* f : {"viewer.js", "viewer.css"}) write_text(temp / f, read_text(web_dir / f));
    std::string html = read_text(web_dir / "index.html");
    const std::string marker = "<!--export-data-->";
    const auto at = html.find(marker);
    if (at == std::string::npos) throw InputError("'" + (web_dir / "index.html").string() + "' lacks " + marker);
    html.replace(at, marker.size(), "<script src=\"data/index.js\"></script>");
    write_text(temp / "index.html", html);
    folder.commit();
    return w.summary;
}

}  // namespace bvc3d::view

#include "bvc3d/core/atomic_file.hpp"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

namespace {
std::atomic<unsigned> counter{0};
}

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
    temp_ = target_;
    temp_ += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    const auto dir = target_.has_parent_path() ? target_.parent_path() : std::filesystem::path(".");
    ensure_writable_directory(dir);
}

AtomicFile::~AtomicFile() {
    if (committed_) return;
    if (out_.is_open()) out_.close();
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
}

namespace {
// Why the last write failed: the system's reason when it left one.
std::string write_failure(const std::filesystem::path& target, int error) {
    return "cannot write '" + target.string() + "': " + (error ? std::strerror(error) : "write error");
}
}  // namespace

std::ofstream& AtomicFile::stream() {
    if (!out_.is_open()) {
        errno = 0;
        out_.open(temp_, std::ios::out | std::ios::trunc | std::ios::binary);
        if (!out_) throw InputError(write_failure(target_, errno));
    }
    return out_;
}

void AtomicFile::write(std::string_view bytes) {
    std::ofstream& out = stream();
    errno = 0;
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) throw InputError(write_failure(target_, errno));
}

void AtomicFile::commit() {
    if (out_.is_open()) {
        errno = 0;
        out_.flush();
        if (!out_) throw InputError(write_failure(target_, errno));
        out_.close();
        if (out_.fail()) throw InputError(write_failure(target_, errno));
    }
    std::error_code ec;
    std::filesystem::rename(temp_, target_, ec);
    if (ec) throw InputError("cannot write '" + target_.string() + "': " + ec.message());
    committed_ = true;
}

void write_file_atomically(const std::filesystem::path& target, std::string_view bytes) {
    AtomicFile file(target);
    file.write(bytes);
    file.commit();
}

void ensure_writable_directory(const std::filesystem::path& dir) {
    std::error_code ec;
    if (std::filesystem::exists(dir, ec)) {
        if (!std::filesystem::is_directory(dir, ec))
            throw InputError("output folder '" + dir.string() + "' exists and is not a folder");
    } else {
        // Name the ancestor that is in the way, if one is a file.
        for (auto p = dir.parent_path(); !p.empty() && p != p.root_path(); p = p.parent_path())
            if (std::filesystem::exists(p, ec)) {
                if (!std::filesystem::is_directory(p, ec))
                    throw InputError("cannot create output folder '" + dir.string() + "': '" + p.string() +
                                     "' is not a folder");
                break;
            }
        std::filesystem::create_directories(dir, ec);
        if (ec) throw InputError("cannot create output folder '" + dir.string() + "': " + ec.message());
    }
    if (::access(dir.c_str(), W_OK) != 0)
        throw InputError("output folder '" + dir.string() + "' is not writable: " + std::strerror(errno));
}

}  // namespace bvc3d

#include "bvc3d/core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

namespace {
std::atomic<unsigned> counter{0};
}

// Collects text in 64 KiB blocks and hands each to AtomicFile::append.
class AtomicFile::Buffer : public std::streambuf {
public:
    explicit Buffer(AtomicFile& file) : file_(file) { setp(block_, block_ + sizeof block_); }

protected:
    int_type overflow(int_type c) override {
        if (!drain()) return traits_type::eof();
        if (!traits_type::eq_int_type(c, traits_type::eof())) {
            *pptr() = traits_type::to_char_type(c);
            pbump(1);
        }
        return traits_type::not_eof(c);
    }
    int sync() override { return drain() ? 0 : -1; }

private:
    bool drain() {
        const bool ok = file_.append(pbase(), static_cast<std::size_t>(pptr() - pbase()));
        setp(block_, block_ + sizeof block_);
        return ok;
    }
    AtomicFile& file_;
    char block_[1 << 16];
};

namespace {
std::filesystem::path parent_of(const std::filesystem::path& p) {
    return p.has_parent_path() ? p.parent_path() : std::filesystem::path(".");
}
}  // namespace

AtomicFile::AtomicFile(std::filesystem::path target) : target_(without_trailing_slash(target)) {
    require_not_directory(target_, "output file");
    temp_ = target_;
    temp_ += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    created_ = ensure_writable_directory(parent_of(target_));
}

AtomicFile::~AtomicFile() {
    stream_.reset();
    buffer_.reset();
    if (fd_ >= 0) ::close(fd_);
    if (committed_) return;
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
    remove_empty_folders(parent_of(target_), created_);
}

void AtomicFile::fail(int error) const {
    throw InputError("cannot write '" + target_.string() + "': " + std::strerror(error));
}

void AtomicFile::open() {
    if (fd_ >= 0) return;
    fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd_ < 0) fail(errno);
}

bool AtomicFile::append(const char* data, std::size_t n) {
    if (error_) return false;
    if (fd_ < 0) {
        fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
        if (fd_ < 0) {
            error_ = errno;
            return false;
        }
    }
    while (n > 0) {
        const ssize_t k = ::write(fd_, data, n);
        if (k < 0) {
            if (errno == EINTR) continue;
            error_ = errno;
            return false;
        }
        data += k;
        n -= static_cast<std::size_t>(k);
    }
    return true;
}

std::ostream& AtomicFile::stream() {
    if (!stream_) {
        open();
        buffer_ = std::make_unique<Buffer>(*this);
        stream_ = std::make_unique<std::ostream>(buffer_.get());
    }
    return *stream_;
}

void AtomicFile::write(std::string_view bytes) {
    if (stream_) stream_->flush();
    if (!append(bytes.data(), bytes.size())) fail(error_);
}

void AtomicFile::commit() {
    if (stream_) stream_->flush();
    if (error_) fail(error_);
    open();
    // close() can report a delayed write error (network file systems): check it too.
    const int fd = fd_;
    fd_ = -1;
    if (::close(fd) != 0) fail(errno);
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

std::filesystem::path ensure_writable_directory(const std::filesystem::path& path) {
    const std::filesystem::path dir = without_trailing_slash(path);
    std::filesystem::path created;
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
        created = dir;
        while (created.has_parent_path() && created.parent_path() != created &&
               !std::filesystem::exists(created.parent_path(), ec))
            created = created.parent_path();
        std::filesystem::create_directories(dir, ec);
        if (ec) throw InputError("cannot create output folder '" + dir.string() + "': " + ec.message());
    }
    if (::access(dir.c_str(), W_OK) != 0)
        throw InputError("output folder '" + dir.string() + "' is not writable: " + std::strerror(errno));
    return created;
}

void remove_empty_folders(const std::filesystem::path& dir, const std::filesystem::path& top) {
    if (top.empty()) return;
    std::error_code ec;
    for (auto p = without_trailing_slash(dir); !p.empty(); p = p.parent_path()) {
        if (!std::filesystem::remove(p, ec)) return;  // not empty (or gone): stop, as remove() only takes empty ones
        if (p == top || !p.has_parent_path() || p.parent_path() == p) return;
    }
}

std::filesystem::path without_trailing_slash(const std::filesystem::path& path) {
    std::string s = path.string();
    while (s.size() > 1 && s.back() == '/') s.pop_back();
    return s;
}

AtomicFolder::AtomicFolder(const std::filesystem::path& target) : target_(without_trailing_slash(target)) {
    std::error_code ec;
    if (std::filesystem::exists(target_, ec) && !std::filesystem::is_directory(target_, ec))
        throw InputError("output folder '" + target_.string() + "' exists and is not a folder");
    created_ = ensure_writable_directory(parent_of(target_));
    temp_ = target_;
    temp_ += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
    std::filesystem::remove_all(temp_, ec);
    if (!std::filesystem::create_directory(temp_, ec))
        throw InputError("cannot create '" + temp_.string() + "' for output folder '" + target_.string() +
                         "': " + (ec ? ec.message() : std::string("it exists")));
}

AtomicFolder::~AtomicFolder() {
    if (committed_) return;
    std::error_code ec;
    std::filesystem::remove_all(temp_, ec);
    remove_empty_folders(parent_of(target_), created_);
}

void AtomicFolder::commit() {
    std::error_code ec;
    std::filesystem::path old;
    if (std::filesystem::exists(target_, ec)) {
        old = target_;
        old += ".old" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
        std::filesystem::rename(target_, old, ec);
        if (ec) throw InputError("cannot replace output folder '" + target_.string() + "': " + ec.message());
    }
    std::filesystem::rename(temp_, target_, ec);
    if (ec) {
        std::error_code back;
        if (!old.empty()) std::filesystem::rename(old, target_, back);
        throw InputError("cannot write output folder '" + target_.string() + "': " + ec.message());
    }
    committed_ = true;
    if (!old.empty()) std::filesystem::remove_all(old, ec);
}

void require_not_directory(const std::filesystem::path& path, const std::string& what) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
        throw InputError(what + " '" + path.string() + "' is a folder, not a file");
}

}  // namespace bvc3d

#include "bvc3d/recording/file_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace bvc3d::recording::detail {

namespace fs = std::filesystem;

namespace {

std::string errno_text() { return std::strerror(errno); }

// Closes the descriptor on every path out of a function.
class FileDescriptor {
public:
    explicit FileDescriptor(int fd) : fd_(fd) {}
    ~FileDescriptor() {
        if (fd_ >= 0) ::close(fd_);
    }
    FileDescriptor(const FileDescriptor&) = delete;
    FileDescriptor& operator=(const FileDescriptor&) = delete;
    int get() const { return fd_; }

private:
    int fd_;
};

void check_is_readable_file(const fs::path& file) {
    std::error_code ec;
    const auto status = fs::status(file, ec);
    if (status.type() == fs::file_type::not_found) throw input_error(file, "no such file");
    if (ec) throw input_error(file, "cannot access: " + ec.message());
    if (fs::is_directory(status)) throw input_error(file, "is a folder, expected a file");
    if (!fs::is_regular_file(status)) throw input_error(file, "not a regular file");
}

void read_exactly(int fd, const fs::path& file, char* out, std::size_t size) {
    std::size_t done = 0;
    while (done < size) {
        const ssize_t n = ::read(fd, out + done, size - done);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw input_error(file, "cannot read: " + errno_text());
        if (n == 0) throw input_error(file, "cannot read: the file shrank while being read");
        done += static_cast<std::size_t>(n);
    }
}

}  // namespace

InputError input_error(const fs::path& file, std::string_view where, std::string_view reason) {
    std::string message = file.string();
    if (!where.empty()) message.append(": ").append(where);
    message.append(": ").append(reason);
    return InputError(message);
}

InputError input_error(const fs::path& file, std::string_view reason) { return input_error(file, {}, reason); }

std::string line_ref(std::size_t line) { return "line " + std::to_string(line); }
std::string point_ref(std::size_t point) { return "point " + std::to_string(point); }

std::string read_file(const fs::path& file) {
    check_is_readable_file(file);
    FileDescriptor fd(::open(file.c_str(), O_RDONLY | O_CLOEXEC));
    if (fd.get() < 0) throw input_error(file, "cannot open: " + errno_text());
    struct stat info {};
    if (::fstat(fd.get(), &info) != 0) throw input_error(file, "cannot read: " + errno_text());
    if (info.st_size == 0) throw input_error(file, "empty file");
    std::string bytes(static_cast<std::size_t>(info.st_size), '\0');
    read_exactly(fd.get(), file, bytes.data(), bytes.size());
    return bytes;
}

}  // namespace bvc3d::recording::detail

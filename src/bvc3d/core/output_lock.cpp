#include "bvc3d/core/output_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d {

namespace {

std::string holder_of(const std::filesystem::path& lock_file) {
    std::ifstream in(lock_file);
    std::string line;
    std::getline(in, line);
    return line.empty() ? std::string("another process") : line;
}

std::string host_name() {
    char buf[256] = {};
    if (::gethostname(buf, sizeof buf - 1) != 0) return "?";
    return buf;
}

}  // namespace

OutputLock::OutputLock(std::filesystem::path lock_file, const std::string& what, std::filesystem::path empty_dir,
                       std::filesystem::path empty_top)
    : path_(std::move(lock_file)), empty_dir_(std::move(empty_dir)), empty_top_(std::move(empty_top)) {
    // A holder that releases between our open and our flock removes the file it locked: then we
    // hold a lock on a name that is gone, and try again on the new file.
    for (int attempt = 0; attempt < 100; ++attempt) {
        fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
        if (fd_ < 0)
            throw InputError("cannot create the lock file '" + path_.string() + "' for " + what + ": " +
                             std::strerror(errno));
        if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
            const int e = errno;
            ::close(fd_);
            fd_ = -1;
            if (e == EWOULDBLOCK)
                throw InputError(what + " is in use by " + holder_of(path_) + " (lock file '" + path_.string() +
                                 "'); wait for it to finish or stop it, or write elsewhere");
            throw InputError("cannot lock '" + path_.string() + "' for " + what + ": " + std::strerror(e));
        }
        struct stat held {
        }, named{};
        if (::fstat(fd_, &held) == 0 && ::stat(path_.c_str(), &named) == 0 && held.st_ino == named.st_ino &&
            held.st_dev == named.st_dev)
            break;
        ::close(fd_);
        fd_ = -1;
    }
    if (fd_ < 0) throw InputError("cannot lock '" + path_.string() + "' for " + what + ": it keeps changing");
    std::ostringstream holder;
    holder << "bvc3d process " << ::getpid() << " on host " << host_name() << "\n";
    const std::string text = holder.str();
    // Best effort: the lock is the flock, the text only makes the message helpful.
    if (::ftruncate(fd_, 0) == 0 && ::write(fd_, text.data(), text.size()) < 0) {}
}

OutputLock::~OutputLock() {
    if (fd_ < 0) return;
    ::unlink(path_.c_str());  // while still holding it: a waiting process then retries on a new file
    ::close(fd_);
    remove_empty_folders(empty_dir_, empty_top_);
}

std::filesystem::path folder_lock_path(const std::filesystem::path& folder) { return folder / ".bvc3d.lock"; }

std::filesystem::path file_lock_path(const std::filesystem::path& file) {
    std::filesystem::path p = file;
    p += ".lock";
    return p;
}

}  // namespace bvc3d

#pragma once
// One writer per output. A lock file beside (or inside) the output, held with flock(2) on an open
// file: the kernel releases it when the process ends, however it ends (SIGKILL, a crash), so a
// lock is never left stuck. The holder writes its pid and host into the file for the message a
// second process prints; the file is removed on release.
#include <filesystem>
#include <string>

namespace bvc3d {

class OutputLock {
public:
    // Takes the lock file `lock_file` for `what` (e.g. "output folder 'results/paper'"); throws
    // InputError if another process holds it, naming `what`, the lock file and the holder.
    // On release, it also removes `empty_dir` and its parents up to `empty_top` if they are empty
    // then: the folders made for an output that an error kept from being written
    // (ensure_writable_directory's return; nothing when empty).
    OutputLock(std::filesystem::path lock_file, const std::string& what, std::filesystem::path empty_dir = {},
               std::filesystem::path empty_top = {});
    ~OutputLock();
    OutputLock(const OutputLock&) = delete;
    OutputLock& operator=(const OutputLock&) = delete;

    const std::filesystem::path& path() const { return path_; }

private:
    std::filesystem::path path_, empty_dir_, empty_top_;
    int fd_ = -1;
};

// The lock file of an output folder and of a single output file.
std::filesystem::path folder_lock_path(const std::filesystem::path& folder);
std::filesystem::path file_lock_path(const std::filesystem::path& file);

}  // namespace bvc3d

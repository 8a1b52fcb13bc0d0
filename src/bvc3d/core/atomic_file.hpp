#pragma once
// Output files appear whole or not at all: write to a temporary name beside the target, then
// rename over it. A failure (or an exception) leaves no half-written file behind. Missing folders
// of the target are created. Errors are InputErrors naming the target and the reason.
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace bvc3d {

class AtomicFile {
public:
    explicit AtomicFile(std::filesystem::path target);
    ~AtomicFile();  // removes the temporary unless committed
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    const std::filesystem::path& temp_path() const { return temp_; }
    const std::filesystem::path& target() const { return target_; }
    std::ofstream& stream();  // opens the temporary on first use (bytes are written as given)
    // Appends `bytes` to the temporary, throwing (with the system's reason, e.g. a full disk) if the
    // write fails.
    void write(std::string_view bytes);
    void commit();  // flush, close, rename into place

private:
    std::filesystem::path target_, temp_;
    std::ofstream out_;
    bool committed_ = false;
};

// The whole of `bytes` as the file `target`, all or nothing (an AtomicFile written at once).
void write_file_atomically(const std::filesystem::path& target, std::string_view bytes);

// Creates `dir` (and parents) or throws InputError saying why it cannot be written.
void ensure_writable_directory(const std::filesystem::path& dir);

}  // namespace bvc3d

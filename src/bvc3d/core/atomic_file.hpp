#pragma once
// Output files appear whole or not at all: write to a temporary name beside the target, then
// rename over it. A failure (or an exception) leaves no half-written file behind.
#include <filesystem>
#include <fstream>
#include <string>

namespace bvc3d {

class AtomicFile {
public:
    explicit AtomicFile(std::filesystem::path target);
    ~AtomicFile();  // removes the temporary unless committed
    AtomicFile(const AtomicFile&) = delete;
    AtomicFile& operator=(const AtomicFile&) = delete;

    const std::filesystem::path& temp_path() const { return temp_; }
    const std::filesystem::path& target() const { return target_; }
    std::ofstream& stream();  // opens the temporary as text on first use
    void commit();            // flush, close, rename into place

private:
    std::filesystem::path target_, temp_;
    std::ofstream out_;
    bool committed_ = false;
};

// Creates `dir` (and parents) or throws InputError saying why it cannot be written.
void ensure_writable_directory(const std::filesystem::path& dir);

}  // namespace bvc3d

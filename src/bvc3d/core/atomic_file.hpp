#pragma once
// Output files appear whole or not at all: write to a temporary name beside the target, then
// rename over it. A failure (or an exception) leaves no half-written file behind.
// Every write goes through write(2), so a failure names the file and the system's reason
// ("No space left on device", "File too large", ...) as an InputError (exit status 2 in the CLI).
#include <filesystem>
#include <memory>
#include <ostream>
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
    // Text, written to the temporary through a buffer; a write error is reported by commit().
    std::ostream& stream();
    // Appends bytes to the temporary now; throws InputError naming the target and the reason.
    void write(std::string_view bytes);
    void commit();  // flush, close, rename into place (InputError naming the target and the reason)

private:
    class Buffer;
    bool append(const char* data, std::size_t n);  // false (and error_ set) on failure
    [[noreturn]] void fail(int error) const;
    void open();

    std::filesystem::path target_, temp_;
    int fd_ = -1;
    int error_ = 0;  // errno of the first failed write
    std::unique_ptr<Buffer> buffer_;
    std::unique_ptr<std::ostream> stream_;
    bool committed_ = false;
};

// The whole of `bytes` as the file `target`, all or nothing (an AtomicFile written at once).
void write_file_atomically(const std::filesystem::path& target, std::string_view bytes);

// Creates `dir` (and parents) or throws InputError saying why it cannot be written.
void ensure_writable_directory(const std::filesystem::path& dir);

// Refuses (InputError) a path that names a folder where a file is expected: `what` says which
// ("trial file", "--cells").
void require_not_directory(const std::filesystem::path& path, const std::string& what);

}  // namespace bvc3d

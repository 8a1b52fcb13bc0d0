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

    std::filesystem::path target_, temp_, created_;
    int fd_ = -1;
    int error_ = 0;  // errno of the first failed write
    std::unique_ptr<Buffer> buffer_;
    std::unique_ptr<std::ostream> stream_;
    bool committed_ = false;
};

// The whole of `bytes` as the file `target`, all or nothing (an AtomicFile written at once).
void write_file_atomically(const std::filesystem::path& target, std::string_view bytes);

// Creates `dir` (and parents) or throws InputError saying why it cannot be written. Returns the
// topmost folder it created (empty when `dir` existed), for remove_empty_folders.
std::filesystem::path ensure_writable_directory(const std::filesystem::path& dir);

// Removes `dir` and its parents up to `top` while they are empty (what ensure_writable_directory
// created, when an error came before anything was written into it). Nothing when `top` is empty.
void remove_empty_folders(const std::filesystem::path& dir, const std::filesystem::path& top);

// Calls remove_empty_folders(dir, top) when it goes out of scope: on success they hold the output.
struct EmptyFolderCleanup {
    std::filesystem::path dir, top;
    ~EmptyFolderCleanup() { remove_empty_folders(dir, top); }
};

// An output path as the user meant it: "walk/" and "walk//" name the folder (or file) "walk".
std::filesystem::path without_trailing_slash(const std::filesystem::path& path);

// A folder written whole or not at all: fill temp_path() (a new folder beside the target), then
// commit() puts it in the target's place (an existing target is replaced only once the new one is
// there). Without commit (an error), the temporary folder and any parent created are removed.
class AtomicFolder {
public:
    explicit AtomicFolder(const std::filesystem::path& target);
    ~AtomicFolder();
    AtomicFolder(const AtomicFolder&) = delete;
    AtomicFolder& operator=(const AtomicFolder&) = delete;

    const std::filesystem::path& temp_path() const { return temp_; }
    const std::filesystem::path& target() const { return target_; }
    void commit();  // InputError naming the target and the reason

private:
    std::filesystem::path target_, temp_, created_;
    bool committed_ = false;
};

// Refuses (InputError) a path that names a folder where a file is expected: `what` says which
// ("trial file", "--cells").
void require_not_directory(const std::filesystem::path& path, const std::string& what);

}  // namespace bvc3d

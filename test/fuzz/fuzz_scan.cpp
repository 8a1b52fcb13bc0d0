// Scan files (recording::read_scan): the first byte picks the format (.pcd, .ply, .bin), the rest
// is the file.
#include "bvc3d/recording/scan_file.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    static const char* const extensions[] = {".pcd", ".ply", ".bin"};
    const std::string path = bvc3d::fuzz::as_file(data + 1, size - 1, extensions[data[0] % 3]);
    return bvc3d::fuzz::expect_input_errors([&] { bvc3d::recording::read_scan(path); });
}

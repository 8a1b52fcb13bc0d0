// Scan lists and extrinsics (recording::list_scans, parse_extrinsics): the first byte picks which.
#include "bvc3d/recording/extrinsics.hpp"
#include "bvc3d/recording/scan_list.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
    if (data[0] % 2 == 0) return bvc3d::fuzz::expect_input_errors([&] { bvc3d::recording::parse_extrinsics(text); });
    const std::string path = bvc3d::fuzz::as_file(data + 1, size - 1, ".txt");
    return bvc3d::fuzz::expect_input_errors([&] { bvc3d::recording::list_scans(path); });
}

// MCAP files (recording::open_mcap): the whole input is the file; every message of every topic is then
// decoded as its topic's type says and every cloud's points are gathered.
#include "bvc3d/recording/bag.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = bvc3d::fuzz::as_file(data, size, ".mcap");
    return bvc3d::fuzz::expect_input_errors([&] {
        const auto bag = bvc3d::recording::open_mcap(path);
        bvc3d::fuzz::read_every_message(*bag);
    });
}

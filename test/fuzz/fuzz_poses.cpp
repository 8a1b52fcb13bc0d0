// Pose files (recording::read_poses): the first byte picks the format (kitti, tum, matrix, auto).
#include "bvc3d/recording/pose_file.hpp"
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    using bvc3d::recording::PoseFormat;
    static const PoseFormat formats[] = {PoseFormat::kitti, PoseFormat::tum, PoseFormat::matrix, PoseFormat::detect};
    const std::string path = bvc3d::fuzz::as_file(data + 1, size - 1, ".txt");
    return bvc3d::fuzz::expect_input_errors([&] { bvc3d::recording::read_poses(path, formats[data[0] % 4]); });
}

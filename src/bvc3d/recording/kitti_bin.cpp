#include "bvc3d/recording/kitti_bin.hpp"

#include <string>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/recording/cloud_builder.hpp"
#include "bvc3d/recording/file_io.hpp"
#include "bvc3d/recording/parsing.hpp"

namespace bvc3d::recording {

namespace fs = std::filesystem;
using namespace detail;

namespace {
constexpr std::uint64_t point_bytes = 16;  // float32 x, y, z, intensity
}

PointCloud read_kitti_bin(const fs::path& file) {
    const std::string bytes = read_file(file);
    if (bytes.size() % point_bytes != 0)
        throw input_error(file, "size " + std::to_string(bytes.size()) +
                                    " bytes is not a multiple of 16 (float32 x, y, z, intensity per point)");
    const CoordinateColumn columns[3] = {{0, point_bytes, 4}, {4, point_bytes, 4}, {8, point_bytes, 4}};
    return gather_points(file, bytes, columns, bytes.size() / point_bytes, ByteOrder::little);
}

void write_kitti_bin(const fs::path& file, const PointCloud& cloud) {
    check_cloud_shape(file, cloud);
    std::string out;
    out.reserve(cloud.size() * point_bytes);
    for (std::size_t i = 0; i < cloud.xyz.size(); i += 3) {
        for (std::size_t axis = 0; axis < 3; ++axis)
            store<float>(out, narrow_to_float(cloud.xyz[i + axis]), ByteOrder::little);
        store<float>(out, 0.0f, ByteOrder::little);  // intensity: unknown
    }
    write_file_atomically(file, out);
}

}  // namespace bvc3d::recording

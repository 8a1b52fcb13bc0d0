#include "bvc3d/recording/extrinsics.hpp"

#include <cmath>
#include <string>

#include "bvc3d/recording/file_io.hpp"
#include "bvc3d/recording/parsing.hpp"

namespace bvc3d::recording {

namespace fs = std::filesystem;
using namespace detail;

namespace {

constexpr double bottom_row_tolerance = 1e-9;

Eigen::Isometry3d from_values(const fs::path& source, const std::vector<double>& v) {
    if (v.size() != 12 && v.size() != 16)
        throw input_error(source, "expected 12 values (row-major 3x4 [R|t]) or 16 (row-major 4x4), found " +
                                      std::to_string(v.size()));
    if (v.size() == 16 && (std::abs(v[12]) > bottom_row_tolerance || std::abs(v[13]) > bottom_row_tolerance ||
                           std::abs(v[14]) > bottom_row_tolerance || std::abs(v[15] - 1) > bottom_row_tolerance))
        throw input_error(source, "the last row of a 4x4 transform must be 0 0 0 1");
    Eigen::Matrix3d rotation;
    Eigen::Vector3d translation;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) rotation(r, c) = v[static_cast<std::size_t>(4 * r + c)];
        translation(r) = v[static_cast<std::size_t>(4 * r + 3)];
    }
    const std::string problem = rotation_problem(rotation);
    if (!problem.empty()) throw input_error(source, problem);
    Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
    transform.linear() = rotation;
    transform.translation() = translation;
    return transform;
}

Eigen::Isometry3d from_text(const fs::path& source, std::string_view text) {
    std::vector<double> values;
    for (const NumberLine& line : read_number_lines(source, text))
        values.insert(values.end(), line.values.begin(), line.values.end());
    return from_values(source, values);
}

}  // namespace

Eigen::Isometry3d read_extrinsics(const fs::path& file) { return from_text(file, read_file(file)); }

Eigen::Isometry3d parse_extrinsics(std::string_view text, std::string_view source) {
    return from_text(fs::path(source), text);
}

void apply_extrinsics(std::vector<PoseRecord>& poses, const Eigen::Isometry3d& base_from_sensor) {
    for (PoseRecord& pose : poses) pose.world_from_sensor = pose.world_from_sensor * base_from_sensor;
}

}  // namespace bvc3d::recording

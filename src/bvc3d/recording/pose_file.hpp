#pragma once
// Sensor poses of a recording. Takes: a pose file. Gives: one world-from-sensor transform per
// line (KITTI, TUM) or per 4-line block (matrix), with its time when the format carries one.
// And writes poses in each format.
//
//  - kitti:  12 numbers per line, the row-major 3×4 [R|t]; no times.
//  - tum:    "t x y z qx qy qz qw" per line; the quaternion is normalized, and is an error when
//            zero or when its norm is off 1 by more than 1e-3.
//  - matrix: four lines per pose, the rows of the 4×4 matrix; the 4th row is "0 0 0 T" and T is
//            the time. When T is exactly 1 in every pose of the file, the matrices are plain
//            homogeneous ones and the poses carry no time.
//  - detect: the format from the content: 12 values per line is kitti, 8 is tum, 4 is matrix;
//            a file that fits none, or mixes them, is an error saying so.
// Values are separated by whitespace and/or commas (a trailing comma is allowed); blank lines and
// lines starting with '#' are skipped. Every value must be finite and every rotation a rotation
// (orthonormal within 1e-4, det > 0). Errors (InputError) name the file, the line and the reason.
#include <Eigen/Geometry>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bvc3d::recording {

struct PoseRecord {
    Eigen::Isometry3d world_from_sensor = Eigen::Isometry3d::Identity();
    std::optional<double> time;  // seconds
    std::size_t line = 0;        // its (first) line in the pose file it was read from; 0: not from a file
};

enum class PoseFormat { kitti, tum, matrix, detect };

// "kitti", "tum", "matrix" or "auto"; anything else is an InputError.
PoseFormat parse_pose_format(std::string_view name);

std::vector<PoseRecord> read_poses(const std::filesystem::path& file, PoseFormat format = PoseFormat::detect);

// The format read_poses(file, detect) would use (never detect), or an InputError saying why none fits.
PoseFormat detect_pose_format(const std::filesystem::path& file);

// Writers: all-or-nothing (temporary + rename); numbers in their shortest exact text.
void write_kitti_poses(const std::filesystem::path& file, const std::vector<PoseRecord>& poses);
// Every pose needs a time.
void write_tum_poses(const std::filesystem::path& file, const std::vector<PoseRecord>& poses);
// Comma-separated rows, each ending in a comma; the 4th row "0,0,0,T," (T = 1 when the poses
// have no times). Either every pose has a time or none.
void write_matrix_poses(const std::filesystem::path& file, const std::vector<PoseRecord>& poses);

// Empty when `rotation` is a proper rotation (orthonormal within 1e-4, det > 0), else why not.
std::string rotation_problem(const Eigen::Matrix3d& rotation);

}  // namespace bvc3d::recording

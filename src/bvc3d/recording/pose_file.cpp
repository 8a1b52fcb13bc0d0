#include "bvc3d/recording/pose_file.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/recording/file_io.hpp"
#include "bvc3d/recording/parsing.hpp"

namespace bvc3d::recording {

namespace fs = std::filesystem;
using namespace detail;

namespace {

constexpr double orthonormal_tolerance = 1e-4;
constexpr double quaternion_norm_tolerance = 1e-3;
constexpr double bottom_row_tolerance = 1e-9;  // the zeros of a matrix pose's 4th row

constexpr const char* formats_by_count = "KITTI has 12 values per line, TUM 8, 4x4 matrix rows 4";

std::string pose_ref(const NumberLine& line, std::size_t pose) {
    return line_ref(line.line) + " (pose " + std::to_string(pose) + ")";
}

void check_value_count(const fs::path& file, const NumberLine& line, std::size_t expected, std::string_view what) {
    if (line.values.size() != expected)
        throw input_error(file, line_ref(line.line),
                          "expected " + std::to_string(expected) + " values (" + std::string(what) + "), found " +
                              std::to_string(line.values.size()));
}

Eigen::Isometry3d rigid(const fs::path& file, const std::string& where, const Eigen::Matrix3d& rotation,
                        const Eigen::Vector3d& translation) {
    const std::string problem = rotation_problem(rotation);
    if (!problem.empty()) throw input_error(file, where, problem);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = rotation;
    pose.translation() = translation;
    return pose;
}

// Rows r0..r0+2 of `rows`, 4 values each: [R|t].
Eigen::Isometry3d from_rows(const fs::path& file, const std::string& where, const std::array<const double*, 3>& rows) {
    Eigen::Matrix3d rotation;
    Eigen::Vector3d translation;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) rotation(r, c) = rows[static_cast<std::size_t>(r)][c];
        translation(r) = rows[static_cast<std::size_t>(r)][3];
    }
    return rigid(file, where, rotation, translation);
}

std::vector<PoseRecord> parse_kitti(const fs::path& file, const std::vector<NumberLine>& lines) {
    std::vector<PoseRecord> poses;
    for (const NumberLine& line : lines) {
        check_value_count(file, line, 12, "a KITTI pose: the row-major 3x4 [R|t]");
        const double* v = line.values.data();
        poses.push_back({from_rows(file, pose_ref(line, poses.size()), {v, v + 4, v + 8}), std::nullopt, line.line});
    }
    return poses;
}

std::vector<PoseRecord> parse_tum(const fs::path& file, const std::vector<NumberLine>& lines) {
    std::vector<PoseRecord> poses;
    for (const NumberLine& line : lines) {
        check_value_count(file, line, 8, "a TUM pose: t x y z qx qy qz qw");
        const std::vector<double>& v = line.values;
        const std::string where = pose_ref(line, poses.size());
        Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
        const double norm = q.norm();
        if (norm == 0) throw input_error(file, where, "zero quaternion");
        if (std::abs(norm - 1) > quaternion_norm_tolerance)
            throw input_error(file, where,
                              "quaternion norm " + std::to_string(norm) + " is not 1 (within 1e-3): not a rotation");
        q.normalize();
        poses.push_back({rigid(file, where, q.toRotationMatrix(), {v[1], v[2], v[3]}), v[0], line.line});
    }
    return poses;
}

std::vector<PoseRecord> parse_matrix(const fs::path& file, const std::vector<NumberLine>& lines) {
    if (lines.size() % 4 != 0) {
        const NumberLine& first_row = lines[lines.size() - lines.size() % 4];
        throw input_error(
            file, line_ref(first_row.line),
            "truncated: the last pose has only " + std::to_string(lines.size() % 4) + " of its 4 matrix rows");
    }
    std::vector<PoseRecord> poses;
    bool all_times_one = true;
    for (std::size_t first = 0; first < lines.size(); first += 4) {
        for (std::size_t r = 0; r < 4; ++r)
            check_value_count(file, lines[first + r], 4, "one row of a 4x4 pose matrix");
        const std::vector<double>& bottom = lines[first + 3].values;
        if (std::abs(bottom[0]) > bottom_row_tolerance || std::abs(bottom[1]) > bottom_row_tolerance ||
            std::abs(bottom[2]) > bottom_row_tolerance)
            throw input_error(file, line_ref(lines[first + 3].line),
                              "the 4th row of a pose matrix must be 0 0 0 T (T the pose's time)");
        const std::array<const double*, 3> rows = {lines[first].values.data(), lines[first + 1].values.data(),
                                                   lines[first + 2].values.data()};
        poses.push_back({from_rows(file, pose_ref(lines[first], poses.size()), rows), bottom[3], lines[first].line});
        all_times_one = all_times_one && bottom[3] == 1;
    }
    if (all_times_one)  // plain homogeneous matrices: no times
        for (PoseRecord& pose : poses) pose.time.reset();
    return poses;
}

std::optional<PoseFormat> format_with_values_per_line(std::size_t n) {
    if (n == 12) return PoseFormat::kitti;
    if (n == 8) return PoseFormat::tum;
    if (n == 4) return PoseFormat::matrix;
    return std::nullopt;
}

PoseFormat detect(const fs::path& file, const std::vector<NumberLine>& lines) {
    const NumberLine& first = lines.front();
    const auto format = format_with_values_per_line(first.values.size());
    if (!format)
        throw input_error(file, line_ref(first.line),
                          "cannot tell the pose format: " + std::to_string(first.values.size()) + " values per line (" +
                              formats_by_count + ")");
    for (const NumberLine& line : lines)
        if (line.values.size() != first.values.size())
            throw input_error(file, line_ref(line.line),
                              "cannot tell the pose format: " + std::to_string(line.values.size()) +
                                  " values here but " + std::to_string(first.values.size()) + " on " +
                                  line_ref(first.line) + " (" + formats_by_count + ")");
    return *format;
}

std::vector<NumberLine> read_pose_lines(const fs::path& file) {
    std::vector<NumberLine> lines = read_number_lines(file, read_file(file));
    if (lines.empty()) throw input_error(file, "no poses: only blank lines and comments");
    return lines;
}

// ---- Writing ----

void append_values(std::string& out, std::initializer_list<double> values, std::string_view separator,
                   std::string_view end) {
    bool first = true;
    for (const double v : values) {
        if (!first) out += separator;
        append_number(out, v);
        first = false;
    }
    out += end;
}

// Either every pose has a time or none; true when all have one.
bool all_or_no_times(const fs::path& file, const std::vector<PoseRecord>& poses) {
    const auto timed = [](const PoseRecord& p) { return p.time.has_value(); };
    const auto count = std::count_if(poses.begin(), poses.end(), timed);
    if (count != 0 && count != static_cast<std::ptrdiff_t>(poses.size())) {
        const auto untimed = std::find_if_not(poses.begin(), poses.end(), timed) - poses.begin();
        throw input_error(file,
                          "cannot write pose " + std::to_string(untimed) + " without a time when other poses have one");
    }
    return count != 0;
}

}  // namespace

PoseFormat parse_pose_format(std::string_view name) {
    if (name == "kitti") return PoseFormat::kitti;
    if (name == "tum") return PoseFormat::tum;
    if (name == "matrix") return PoseFormat::matrix;
    if (name == "auto") return PoseFormat::detect;
    throw InputError("unknown pose format " + quote_token(name) + ": expected kitti, tum, matrix or auto");
}

std::vector<PoseRecord> read_poses(const fs::path& file, PoseFormat format) {
    const std::vector<NumberLine> lines = read_pose_lines(file);
    if (format == PoseFormat::detect) format = detect(file, lines);
    switch (format) {
        case PoseFormat::kitti:
            return parse_kitti(file, lines);
        case PoseFormat::tum:
            return parse_tum(file, lines);
        case PoseFormat::matrix:
            return parse_matrix(file, lines);
        case PoseFormat::detect:
            break;
    }
    throw input_error(file, "unknown pose format");
}

PoseFormat detect_pose_format(const fs::path& file) { return detect(file, read_pose_lines(file)); }

void write_kitti_poses(const fs::path& file, const std::vector<PoseRecord>& poses) {
    std::string out;
    for (const PoseRecord& pose : poses) {
        const Eigen::Matrix4d m = pose.world_from_sensor.matrix();
        append_values(out,
                      {m(0, 0), m(0, 1), m(0, 2), m(0, 3), m(1, 0), m(1, 1), m(1, 2), m(1, 3), m(2, 0), m(2, 1),
                       m(2, 2), m(2, 3)},
                      " ", "\n");
    }
    write_file_atomically(file, out);
}

void write_tum_poses(const fs::path& file, const std::vector<PoseRecord>& poses) {
    std::string out = "# t x y z qx qy qz qw\n";
    for (std::size_t i = 0; i < poses.size(); ++i) {
        if (!poses[i].time)
            throw input_error(file, "cannot write pose " + std::to_string(i) + " without a time as TUM");
        const Eigen::Vector3d t = poses[i].world_from_sensor.translation();
        const Eigen::Quaterniond q(poses[i].world_from_sensor.rotation());
        append_values(out, {*poses[i].time, t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}, " ", "\n");
    }
    write_file_atomically(file, out);
}

void write_matrix_poses(const fs::path& file, const std::vector<PoseRecord>& poses) {
    const bool timed = all_or_no_times(file, poses);
    std::string out;
    for (const PoseRecord& pose : poses) {
        const Eigen::Matrix4d m = pose.world_from_sensor.matrix();
        for (int r = 0; r < 3; ++r) append_values(out, {m(r, 0), m(r, 1), m(r, 2), m(r, 3)}, ",", ",\n");
        append_values(out, {0.0, 0.0, 0.0, timed ? *pose.time : 1.0}, ",", ",\n");
    }
    write_file_atomically(file, out);
}

std::string rotation_problem(const Eigen::Matrix3d& rotation) {
    const double deviation = (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (!(deviation <= orthonormal_tolerance))
        return "not a rotation: max |R^T R - I| = " + std::to_string(deviation) + " exceeds 1e-4";
    if (!(rotation.determinant() > 0))
        return "not a rotation: determinant " + std::to_string(rotation.determinant()) + " (a reflection)";
    return {};
}

}  // namespace bvc3d::recording

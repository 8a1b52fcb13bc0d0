#pragma once
// A fixed sensor mounting. Takes: the base-from-sensor transform as 12 numbers (row-major 3×4
// [R|t]) or 16 (row-major 4×4 with last row 0 0 0 1), from a text file or a string (e.g. a
// command-line value), separated by whitespace and/or commas ('#' comment lines allowed).
// Gives: the transform, and poses of the base turned into poses of the sensor:
// world_from_sensor = world_from_base · base_from_sensor.
// Bad values (count, non-finite, not a rotation, bad last row) are InputErrors naming the source.
#include <Eigen/Geometry>
#include <filesystem>
#include <string_view>
#include <vector>

#include "bvc3d/recording/pose_file.hpp"

namespace bvc3d::recording {

Eigen::Isometry3d read_extrinsics(const std::filesystem::path& file);

// `text` holds the numbers; `source` names it in errors (say "--extrinsics").
Eigen::Isometry3d parse_extrinsics(std::string_view text, std::string_view source = "extrinsics");

// Each pose, given as world_from_base, becomes world_from_base · base_from_sensor.
void apply_extrinsics(std::vector<PoseRecord>& poses, const Eigen::Isometry3d& base_from_sensor);

}  // namespace bvc3d::recording

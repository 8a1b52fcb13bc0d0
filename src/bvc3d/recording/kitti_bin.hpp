#pragma once
// KITTI velodyne scans (.bin). Takes: a file of float32 x, y, z, intensity repeated, little-endian,
// no header. Gives: x, y, z as a PointCloud (intensity dropped; NaN/inf points dropped and
// counted). And writes clouds in the same layout, with intensity 0.
// The size must be a non-zero multiple of 16 bytes, else InputError naming the file.
#include <filesystem>

#include "bvc3d/recording/point_cloud.hpp"

namespace bvc3d::recording {

PointCloud read_kitti_bin(const std::filesystem::path& file);

// All-or-nothing (temporary + rename); coordinates rounded to float32.
void write_kitti_bin(const std::filesystem::path& file, const PointCloud& cloud);

}  // namespace bvc3d::recording

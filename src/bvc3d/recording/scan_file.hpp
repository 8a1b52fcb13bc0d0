#pragma once
// One scan file of any supported format. Takes: a path. Gives: its PointCloud, the reader chosen
// by the extension (.pcd, .ply, .bin as KITTI velodyne; any letter case). An unknown extension is
// an InputError naming the file.
#include <filesystem>
#include <optional>

#include "bvc3d/recording/point_cloud.hpp"

namespace bvc3d::recording {

enum class ScanFormat { pcd, ply, kitti_bin };

// The format a file name says, or nothing for an unknown extension.
std::optional<ScanFormat> scan_format_of(const std::filesystem::path& file);

PointCloud read_scan(const std::filesystem::path& file);

}  // namespace bvc3d::recording

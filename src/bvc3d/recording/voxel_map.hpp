#pragma once
// A point map from many scans: the union of their points in the world frame, downsampled on a
// voxel grid (one point per occupied voxel: the mean of the points in it). Takes: scans with their
// poses, one at a time. Gives: the map as a PointCloud, in a fixed order (voxels sorted by index).
#include <Eigen/Geometry>
#include <cstdint>
#include <unordered_map>

#include "bvc3d/recording/point_cloud.hpp"

namespace bvc3d::recording {

struct VoxelMapParams {
    double voxel = 0.05;     // m, the grid's edge (voxel (i, j, k) holds floor(p / voxel) = (i, j, k))
    double min_range = 0.0;  // m: points nearer their sensor are left out (the carrier)
    double max_range = 0.0;  // m: points farther are left out; 0 keeps every range
    int min_points = 1;      // voxels with fewer points are left out (sparse noise)
};

class VoxelMap {
public:
    explicit VoxelMap(VoxelMapParams params);  // InputError for a non-positive voxel or bad limits
    // Adds a scan's points (sensor frame) placed by `world_from_sensor`.
    void add(const PointCloud& scan, const Eigen::Isometry3d& world_from_sensor);
    std::size_t points_added() const { return added_; }
    std::size_t voxels() const { return cells_.size(); }
    // The map: one point per voxel with at least min_points points.
    PointCloud cloud() const;

private:
    struct Cell {
        double x = 0, y = 0, z = 0;
        std::uint64_t count = 0;
    };
    VoxelMapParams p_;
    std::unordered_map<std::uint64_t, Cell> cells_;
    std::size_t added_ = 0;
};

}  // namespace bvc3d::recording

#pragma once
// Shortest paths in 3-D for the flying agent (SPEC §17's yardstick on voxels, docs/navigation.md#shortest-path).
// Takes: an occupancy of nx × ny × nz cubic voxels (true where the flying body fits, obstacles already inflated)
// and two voxels. Gives: the length of a shortest path through free voxels (26 neighbours at 1, √2 or √3 voxels;
// a diagonal move only when every voxel of its box is free, so it never cuts an obstacle's edge or corner), or
// none. The occupancy of a world (voxel_occupancy) comes from the flying body's collider (sphere_collider.hpp): a
// voxel is free when the body fits at its centre and the nearest geometry (the flight volume's floor, ceiling and
// sides included) is at least `inflate` m away, as the floor's grid inflates obstacles (shortest_path.hpp).
#include <array>
#include <optional>
#include <vector>

#include "bvc3d/agent/sphere_collider.hpp"
#include "bvc3d/core/geometry.hpp"

namespace bvc3d {

struct VoxelGrid3 {
    int nx = 0, ny = 0, nz = 0;
    double cell = 0.1;           // m
    std::vector<char> free;      // x fastest, then y, then z
    Vec3 origin = Vec3::Zero();  // the corner of voxel (0, 0, 0)
    bool inside(int x, int y, int z) const { return x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz; }
    std::size_t index(int x, int y, int z) const { return (std::size_t(z) * ny + y) * nx + x; }
    bool usable(int x, int y, int z) const { return inside(x, y, z) && free[index(x, y, z)]; }
    std::size_t size() const { return free.size(); }
    std::array<int, 3> voxel_at(std::size_t i) const {
        return {int(i % std::size_t(nx)), int(i / std::size_t(nx) % std::size_t(ny)),
                int(i / (std::size_t(nx) * std::size_t(ny)))};
    }
    Vec3 center(std::array<int, 3> v) const { return origin + cell * Vec3(v[0] + 0.5, v[1] + 0.5, v[2] + 0.5); }
    std::optional<std::array<int, 3>> voxel_of(const Vec3& p) const;  // none outside the grid
};

// Voxels of `cell` m over the box the body's centre can be in (SphereCollider::center_box), free where the body
// fits at the centre (is_free) with the nearest geometry at least `inflate` m from it (clearance + radius).
VoxelGrid3 voxel_occupancy(const SphereCollider& body, double cell = 0.1, double inflate = 0.5);

// Connected parts of the free voxels (6 neighbours: the moves of voxel_shortest_path connect the same voxels): a
// label per voxel (-1 where not free) and their number.
std::vector<int> voxel_parts(const VoxelGrid3& grid, int& count);

// The free voxel nearest to p (by the distance to its centre; ties by index), p's own if it is free; none if no
// voxel is free.
std::optional<std::array<int, 3>> nearest_free_voxel(const VoxelGrid3& grid, const Vec3& p);

// The shortest path between two points (SPEC §17's yardstick in 3-D): each end joined by a straight segment to its
// nearest free voxel, which counts, and voxel_shortest_path between those; none if unreachable.
std::optional<double> voxel_path_between(const VoxelGrid3& grid, const Vec3& from, const Vec3& to);

// The length (m) of a shortest path from voxel `from` to voxel `to` (centre to centre), none if unreachable.
std::optional<double> voxel_shortest_path(const VoxelGrid3& grid, std::array<int, 3> from, std::array<int, 3> to);

}  // namespace bvc3d

#pragma once
// Shortest paths in 3-D for the flying agent (SPEC §17's yardstick on voxels, docs/navigation.md#shortest-path).
// Takes: an occupancy of nx × ny × nz cubic voxels (true where the flying body fits, obstacles already inflated)
// and two voxels. Gives: the length of a shortest path through free voxels (26 neighbours at 1, √2 or √3 voxels;
// a diagonal move only when every voxel of its box is free, so it never cuts an obstacle's edge or corner), or
// none. Turning a world's geometry into this occupancy (from the flying body's collider) is not written yet.
#include <array>
#include <optional>
#include <vector>

namespace bvc3d {

struct VoxelGrid3 {
    int nx = 0, ny = 0, nz = 0;
    double cell = 0.1;       // m
    std::vector<char> free;  // x fastest, then y, then z
    bool inside(int x, int y, int z) const { return x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < nz; }
    std::size_t index(int x, int y, int z) const { return (std::size_t(z) * ny + y) * nx + x; }
    bool usable(int x, int y, int z) const { return inside(x, y, z) && free[index(x, y, z)]; }
};

// The length (m) of a shortest path from voxel `from` to voxel `to` (centre to centre), none if unreachable.
std::optional<double> voxel_shortest_path(const VoxelGrid3& grid, std::array<int, 3> from, std::array<int, 3> to);

}  // namespace bvc3d

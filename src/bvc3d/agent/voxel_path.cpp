#include "bvc3d/agent/voxel_path.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <queue>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

std::optional<std::array<int, 3>> VoxelGrid3::voxel_of(const Vec3& p) const {
    std::array<int, 3> v{};
    const int n[3] = {nx, ny, nz};
    for (int d = 0; d < 3; ++d) {
        const double f = std::floor((p[d] - origin[d]) / cell);
        if (!(f >= 0 && f < n[d])) return std::nullopt;
        v[std::size_t(d)] = int(f);
    }
    return v;
}

VoxelGrid3 voxel_occupancy(const SphereCollider& body, double cell, double inflate) {
    if (!(cell > 0)) throw InputError("voxel occupancy: the voxel size must be > 0");
    const auto& box = body.center_box();
    VoxelGrid3 g;
    g.cell = cell;
    g.origin = box.min();
    g.nx = std::max(1, int(std::ceil(box.sizes().x() / cell)));
    g.ny = std::max(1, int(std::ceil(box.sizes().y() / cell)));
    g.nz = std::max(1, int(std::ceil(box.sizes().z() / cell)));
    if (double(g.nx) * g.ny * g.nz > 5e7)
        throw InputError("voxel occupancy: " + std::to_string(g.nx) + " × " + std::to_string(g.ny) + " × " +
                         std::to_string(g.nz) + " voxels of " + std::to_string(cell) + " m are too many");
    g.free.assign(std::size_t(g.nx) * g.ny * g.nz, 0);
    for (std::size_t i = 0; i < g.free.size(); ++i) {
        const Vec3 c = g.center(g.voxel_at(i));
        g.free[i] = body.is_free(c) && body.clearance(c) + body.radius() >= inflate;
    }
    return g;
}

std::vector<int> voxel_parts(const VoxelGrid3& g, int& count) {
    std::vector<int> label(g.size(), -1);
    std::vector<std::size_t> stack;
    count = 0;
    static constexpr int step[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (std::size_t start = 0; start < g.size(); ++start) {
        if (!g.free[start] || label[start] >= 0) continue;
        label[start] = count;
        stack.assign(1, start);
        while (!stack.empty()) {
            const auto v = g.voxel_at(stack.back());
            stack.pop_back();
            for (const auto& d : step) {
                const int x = v[0] + d[0], y = v[1] + d[1], z = v[2] + d[2];
                if (!g.usable(x, y, z) || label[g.index(x, y, z)] >= 0) continue;
                label[g.index(x, y, z)] = count;
                stack.push_back(g.index(x, y, z));
            }
        }
        ++count;
    }
    return label;
}

std::optional<std::array<int, 3>> nearest_free_voxel(const VoxelGrid3& g, const Vec3& p) {
    if (const auto own = g.voxel_of(p); own && g.free[g.index((*own)[0], (*own)[1], (*own)[2])]) return own;
    double best = std::numeric_limits<double>::infinity();
    std::optional<std::array<int, 3>> found;
    for (std::size_t i = 0; i < g.size(); ++i) {
        if (!g.free[i]) continue;
        const double d = (g.center(g.voxel_at(i)) - p).squaredNorm();
        if (d < best) best = d, found = g.voxel_at(i);
    }
    return found;
}

std::optional<double> voxel_path_between(const VoxelGrid3& g, const Vec3& from, const Vec3& to) {
    const auto a = nearest_free_voxel(g, from), b = nearest_free_voxel(g, to);
    if (!a || !b) return std::nullopt;
    const auto inner = voxel_shortest_path(g, *a, *b);
    if (!inner) return std::nullopt;
    return (from - g.center(*a)).norm() + *inner + (g.center(*b) - to).norm();
}

std::optional<double> voxel_shortest_path(const VoxelGrid3& g, std::array<int, 3> from, std::array<int, 3> to) {
    if (!g.usable(from[0], from[1], from[2]) || !g.usable(to[0], to[1], to[2])) return std::nullopt;
    // Octile distance in 3-D: an admissible, consistent heuristic for these moves.
    const auto h = [&](int x, int y, int z) {
        std::array<double, 3> d{double(std::abs(x - to[0])), double(std::abs(y - to[1])), double(std::abs(z - to[2]))};
        std::sort(d.begin(), d.end());
        return g.cell * (d[0] * std::sqrt(3.0) + (d[1] - d[0]) * std::sqrt(2.0) + (d[2] - d[1]));
    };
    std::vector<double> dist(g.free.size(), std::numeric_limits<double>::infinity());
    std::vector<char> closed(g.free.size(), 0);
    using Open = std::pair<double, std::size_t>;
    std::priority_queue<Open, std::vector<Open>, std::greater<Open>> open;
    const std::size_t start = g.index(from[0], from[1], from[2]), goal = g.index(to[0], to[1], to[2]);
    dist[start] = 0;
    open.push({h(from[0], from[1], from[2]), start});
    while (!open.empty()) {
        const std::size_t c = open.top().second;
        open.pop();
        if (closed[c]) continue;
        closed[c] = 1;
        if (c == goal) return dist[c];
        const int x = int(c % std::size_t(g.nx)), y = int(c / std::size_t(g.nx) % std::size_t(g.ny)),
                  z = int(c / (std::size_t(g.nx) * std::size_t(g.ny)));
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    if ((dx | dy | dz) == 0 || !g.usable(x + dx, y + dy, z + dz)) continue;
                    bool box_free = true;  // every voxel of the move's box
                    for (int ez = std::min(0, dz); ez <= std::max(0, dz) && box_free; ++ez)
                        for (int ey = std::min(0, dy); ey <= std::max(0, dy) && box_free; ++ey)
                            for (int ex = std::min(0, dx); ex <= std::max(0, dx) && box_free; ++ex)
                                box_free = g.usable(x + ex, y + ey, z + ez);
                    if (!box_free) continue;
                    const std::size_t n = g.index(x + dx, y + dy, z + dz);
                    const double d = dist[c] + g.cell * std::sqrt(double(dx * dx + dy * dy + dz * dz));
                    if (closed[n] || d >= dist[n]) continue;
                    dist[n] = d;
                    open.push({d + h(x + dx, y + dy, z + dz), n});
                }
    }
    return std::nullopt;
}

}  // namespace bvc3d

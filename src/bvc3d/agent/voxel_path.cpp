#include "bvc3d/agent/voxel_path.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <queue>

namespace bvc3d {

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

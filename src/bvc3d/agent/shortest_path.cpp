#include "bvc3d/agent/shortest_path.hpp"

#include <cmath>
#include <limits>

#include "bvc3d/agent/grid_path.hpp"

namespace bvc3d {

std::optional<GridCell> nearest_usable_cell(const FreeSpaceGrid& grid, const Vec2& p, double inflate) {
    const auto own = grid.cell_of(p);
    if (!own) return std::nullopt;
    if (grid.fits(*own, inflate)) return own;
    double best = std::numeric_limits<double>::infinity();
    std::optional<GridCell> found;
    for (std::size_t i = 0; i < grid.size(); ++i) {
        const GridCell c = grid.cell_at(i);
        if (!grid.fits(c, inflate)) continue;
        const double d = (grid.center(c) - p).squaredNorm();
        if (d < best) best = d, found = c;
    }
    return found;
}

ShortestPath shortest_path(const FreeSpaceGrid& grid, const Vec2& from, const Vec2& to, double inflate) {
    ShortestPath out;
    const auto a = nearest_usable_cell(grid, from, inflate);
    const auto b = nearest_usable_cell(grid, to, inflate);
    if (!a || !b) return out;
    const auto cells = GridPathFinder(grid, inflate).shortest_path(*a, *b);
    if (cells.empty()) return out;
    out.found = true;
    out.points.push_back(from);
    for (const GridCell& c : cells) out.points.push_back(grid.center(c));
    out.points.push_back(to);
    for (std::size_t i = 1; i < out.points.size(); ++i) out.length += (out.points[i] - out.points[i - 1]).norm();
    return out;
}

}  // namespace bvc3d

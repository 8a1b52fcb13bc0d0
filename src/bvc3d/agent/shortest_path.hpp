#pragma once
// The shortest path of SPEC §17, the yardstick of navigation (docs/navigation.md#shortest-path): A* on a
// 0.1 m grid of the floor with obstacles inflated by 0.5 m. A navigation's path ratio is its travelled
// path divided by this length.
// Takes: a floor's FreeSpaceGrid (free_space_grid.hpp) and two points. Gives: the path's length and
// points, from the points themselves through the grid's usable cells (grid_path.hpp's A*: 8 neighbours,
// a diagonal only when both cells beside it are usable).
//
// An end whose own cell is not usable (closer than the inflation to an obstacle: a goal beside a wall)
// is joined to the nearest usable cell by a straight segment, counted in the length: the body still
// reaches it, and the yardstick stays defined. Ends outside the grid or in a part of the floor the other
// end cannot reach give no path.
#include <optional>
#include <vector>

#include "bvc3d/agent/free_space_grid.hpp"

namespace bvc3d {

struct ShortestPathParams {
    double cell = 0.1;     // m, grid cell
    double inflate = 0.5;  // m, obstacles inflated by this (only cells with this much room are used)
};

struct ShortestPath {
    bool found = false;
    double length = 0.0;       // m, including the segments from the ends to their cells' centres
    std::vector<Vec2> points;  // from, the cells' centres, to
};

// The shortest path on `grid` (whose cell size is the one used) between two points.
ShortestPath shortest_path(const FreeSpaceGrid& grid, const Vec2& from, const Vec2& to, double inflate = 0.5);

// The usable cell (room ≥ inflate) nearest to p (by the distance to its centre; ties by cell index), or
// none when no cell is usable or p lies outside the grid.
std::optional<GridCell> nearest_usable_cell(const FreeSpaceGrid& grid, const Vec2& p, double inflate);

}  // namespace bvc3d

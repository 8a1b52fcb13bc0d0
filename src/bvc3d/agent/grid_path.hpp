#pragma once
// Shortest paths on a floor's free-space grid (docs/buildings.md#routes), for routes, tours and
// navigation (SPEC §17). Takes: a FreeSpaceGrid and a radius (obstacles inflated by it: only cells
// where a disc of that radius fits are used). Gives: A* paths and Dijkstra distances over those cells.
// Moves go to the 8 neighbors (a diagonal one only when both cells beside it are usable too), at
// their length (1 or √2 cells); ties are broken by cell index, so results never depend on anything
// but the grid.
#include <functional>
#include <vector>

#include "bvc3d/agent/free_space_grid.hpp"

namespace bvc3d {

class GridPathFinder {
public:
    GridPathFinder(const FreeSpaceGrid& grid, double radius);
    const FreeSpaceGrid& grid() const { return grid_; }
    bool usable(GridCell c) const { return grid_.contains(c) && grid_.fits(c, radius_); }

    // The cells of a shortest path from `from` to `to`, both included; empty when there is none (or
    // either end is not usable).
    std::vector<GridCell> shortest_path(GridCell from, GridCell to) const;

    // Dijkstra from `from` (distances in m, infinity where unreached). Stops once a cell for which
    // `stop` returns true is settled (and returns it), or at `max_distance`; -1 if none was.
    struct Reach {
        std::vector<float> distance;
        std::vector<int> parent;  // the previous cell's index on a shortest path, -1 at the source
        long long stopped_at = -1;
    };
    Reach reach(GridCell from, const std::function<bool(std::size_t)>& stop = {}, double max_distance = 1e30) const;
    // The cells from the source of `r` to cell index `to`, both included.
    std::vector<GridCell> path_to(const Reach& r, std::size_t to) const;

private:
    const FreeSpaceGrid& grid_;
    double radius_;
};

// A polyline with points dropped while the body (its own radius) can drive straight from the last
// kept point to a later one: the first and last points stay.
std::vector<Vec2> straighten(const std::vector<Vec2>& points, const BodyCollider& body);

}  // namespace bvc3d

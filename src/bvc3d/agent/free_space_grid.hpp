#pragma once
// The free space of a floor on a grid (docs/buildings.md#routes): for every cell center, how far the
// nearest obstacle is (geometry in the body's slab, the walkable region's boundary, drop edges).
// Takes: a BodyCollider (the world as the ground robot's body meets it) and a cell size.
// Gives: per-cell room, the cells where a body of a given radius fits (obstacles inflated by it), and
// their connected parts. Routes, tours and navigation (grid_path.hpp) plan on it.
#include <optional>
#include <vector>

#include "bvc3d/agent/body_collider.hpp"

namespace bvc3d {

struct GridCell {
    int x = 0, y = 0;
    bool operator==(const GridCell&) const = default;
};

class FreeSpaceGrid {
public:
    // Cells of `cell` m over the walkable region's bounds (coarsened for very large floors: at most
    // `max_cells` cells).
    FreeSpaceGrid(const BodyCollider& body, double cell = 0.1, double max_cells = 4e7);

    double cell() const { return cell_; }
    int nx() const { return nx_; }
    int ny() const { return ny_; }
    std::size_t size() const { return room_.size(); }
    std::size_t index(GridCell c) const { return static_cast<std::size_t>(c.y) * nx_ + c.x; }
    GridCell cell_at(std::size_t i) const { return {static_cast<int>(i % nx_), static_cast<int>(i / nx_)}; }
    bool contains(GridCell c) const { return c.x >= 0 && c.y >= 0 && c.x < nx_ && c.y < ny_; }
    Vec2 center(GridCell c) const { return origin_ + Vec2((c.x + 0.5) * cell_, (c.y + 0.5) * cell_); }
    std::optional<GridCell> cell_of(const Vec2& p) const;  // none outside the grid

    // Distance from the cell's center to the nearest obstacle (0 outside the walkable region).
    double room(GridCell c) const { return room_[index(c)]; }
    const std::vector<float>& rooms() const { return room_; }
    // A disc of `radius` fits at the cell's center.
    bool fits(GridCell c, double radius) const { return room_[index(c)] >= radius; }

    // Connected parts of the cells where `radius` fits (8 neighbors): a label per cell (-1 where it
    // does not fit) and the number of parts.
    std::vector<int> parts(double radius, int& count) const;

private:
    Vec2 origin_;
    double cell_ = 0.1;
    int nx_ = 0, ny_ = 0;
    std::vector<float> room_;
};

}  // namespace bvc3d

#pragma once
// Floors of a building (docs/buildings.md#floors): the heights at which a ground agent can stand, and
// where one floor holds it.
// Takes: triangles. Gives: the floor levels (horizontal geometry grouped by height) and the map of a
// floor at z = 0 (which cells lie over it) with the edges where it ends (a stairwell, the edge of a
// slab, a door to the lower ground outside).
#include <array>
#include <vector>

#include "bvc3d/world/mesh.hpp"

namespace bvc3d {

struct FloorLevel {
    double z = 0.0;     // m: where most of the group's area is (its highest top within 1 mm of there)
    double area = 0.0;  // m² of horizontal triangles in the group
};

struct FloorOptions {
    double max_tilt_deg = 2.0;  // a triangle whose normal is within this of vertical is horizontal
    double thickness = 0.05;    // m: horizontal triangles this close in height form one level
    double min_area = 1.0;      // m²: smaller groups (a step, a shelf) are not floors
};

// The levels of the horizontal triangles, lowest first; `skip` (one flag per triangle, or empty)
// leaves triangles out (e.g. Gazebo's ground plane).
std::vector<FloorLevel> floor_levels(const TriangleMesh& mesh, const std::vector<char>& skip = {},
                                     const FloorOptions& options = {});

// A floor at z = 0 on a grid: a cell is held when its center lies over a horizontal triangle whose
// vertices are all within [-thickness, 0] (the floor's own level).
struct FloorMap {
    Eigen::AlignedBox2d box;  // the grid's extent (whole cells)
    double cell = 0.1;        // m
    int nx = 0, ny = 0;
    std::vector<char> held;                   // nx × ny, row y first: held[y·nx + x]
    std::vector<std::array<Vec2, 2>> edges;   // between held and empty cells, merged along grid lines
    bool holds(const Vec2& p) const;          // p lies over a held cell
    Eigen::AlignedBox2d held_bounds() const;  // the box of the held cells (empty if none)
    double held_area() const;
};

FloorMap floor_map(const TriangleMesh& mesh, double cell = 0.1, const FloorOptions& options = {});

}  // namespace bvc3d

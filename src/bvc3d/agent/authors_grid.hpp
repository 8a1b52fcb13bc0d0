#pragma once
// Agent stage: the authors' path planner (SPEC §17.3, their path_planning.py; docs/navigation.md#the-authors-
// protocol): the yardstick and the starts of navigation's `protocol: authors`. Takes: a floor (BodyCollider: the
// geometry in the body's slab and the walkable region), the grid's cell and the obstacles' inflation. Gives: which
// cells are blocked, the optimal path's length from a point to a goal's disc, and starts drawn as theirs.
//
// The grid covers the floor's square: the walkable region's bounds rounded out to whole metres (their 20 × 20 m
// worlds: [−10, 10]²), columns from its west edge and rows from its north edge, a point's cell as their code finds it
// (column int((x − west)/cell), row int((north − y)/cell)). Obstacles are the geometry inside the walkable region
// (the walls that bound it are not: their planner has no outer walls), each segment of it:
//   - axis-aligned: the cells of the index ranges their code marks for a rectangle grown by `inflate`, both ends
//     included (so one cell wider on the east and south sides when an end falls on a cell's edge);
//   - at an angle (walls their planner never had): the cells whose centre lies in the segment grown by `inflate` in
//     its own frame, square ends (a rectangle's four sides give the rectangle grown so);
//   - a point (a corner) adds nothing to its sides; a sphere's disc blocks as the square around it, grown;
// coordinates taken to the nanometre, so that a wall written at −3.4 m is at −3.4 m whatever arithmetic placed it.
// The path: exact shortest paths (Dijkstra) over 8 neighbours with costs cell and cell·√2, corners cut, from the
// start's cell to the nearest cell whose centre lies within `radius` of the goal (their A* is a slightly inexact
// version of the same search: docs/navigation.md). Starts: uniform in the square shrunk by `margin`, x drawn before
// y, kept if their cell is free, they are at least `min_distance` from the goal and the body fits there, then moved
// to their cell's centre; a start whose cell cannot reach the goal is drawn again.
#include <optional>
#include <vector>

#include "bvc3d/agent/body_collider.hpp"
#include "bvc3d/core/random.hpp"

namespace bvc3d {

class AuthorsGrid {
public:
    AuthorsGrid(const BodyCollider& body, double cell = 0.1, double inflate = 0.5);

    int cols() const { return cols_; }
    int rows() const { return rows_; }
    double cell() const { return cell_; }
    double west() const { return west_; }
    double north() const { return north_; }
    // Row-major rows × cols.
    const std::vector<char>& blocked() const { return blocked_; }
    bool blocked(int col, int row) const { return blocked_[std::size_t(row) * std::size_t(cols_) + std::size_t(col)]; }
    // (column, row) of p, or none outside the grid.
    std::optional<std::pair<int, int>> cell_of(const Vec2& p) const;
    Vec2 centre(int col, int row) const;
    // The optimal path's length from p's cell to the goal's disc, and its cells; none when p's cell is blocked or
    // outside, or no cell of the disc can be reached.
    struct Path {
        double length = 0;
        std::vector<std::pair<int, int>> cells;
    };
    std::optional<Path> shortest(const Vec2& from, const Vec2& goal, double radius) const;
    // A start as theirs (see above), drawn from `rng`; InputError when 100 000 candidates give none.
    Vec2 draw_start(Rng& rng, const BodyCollider& body, const Vec2& goal, double min_distance, double margin,
                    double radius) const;

private:
    void block_segment(const Segment2& s, double inflate);
    double cell_;
    int cols_ = 0, rows_ = 0;
    double west_ = 0, north_ = 0, east_ = 0, south_ = 0;
    std::vector<char> blocked_;
};

}  // namespace bvc3d

#pragma once
// Tours (docs/buildings.md#tours): a closed route on a floor's free space that passes within
// `coverage_radius` of at least `min_coverage` of the walkable region and drives part of the
// building a second time in the opposite direction (revisits in both directions are what place
// recognition is tested on).
// Takes: a world and the ground robot's body. Gives: the tour's waypoints and its drive (route.hpp).
//
// How: on the free-space grid, viewpoints are chosen greedily until every part of the walkable region
// (the cells where the body fits, connected to the start) lies within `coverage_radius` − 0.1 m of
// one along free space (never through a wall); they are visited nearest first (Dijkstra on the cells
// clear by the body's radius + `margin`), the cell paths straightened while the body stays `margin`
// clear, and the tour returns to its start. If the drive does not cover `min_reverse` m of the
// building a second time in the opposite direction, it begins with an out-and-back along its first
// part. Nothing is random: the same world gives the same tour.
#include <optional>
#include <vector>

#include "bvc3d/agent/route.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

struct TourParams {
    double coverage_radius = 1.0;  // m
    double min_coverage = 0.9;     // of the walkable region within coverage_radius of the path
    double margin = 0.1;           // m of clearance planned beyond the body's radius
    double min_reverse = 10.0;     // m driven a second time in the opposite direction, at least
    double cell = 0.1;             // m, the free-space grid

    static const params::Table<TourParams>& table();
    void validate() const { table().check(*this); }
};

// What a drive does to a floor.
struct RouteStats {
    double length = 0;          // m of path
    double coverage = 0;        // fraction of the walkable region within coverage_radius of the path
    double walkable_area = 0;   // m² of the walkable region (cells where the body fits, connected to the start)
    double reverse_length = 0;  // m driven within coverage_radius of an earlier part of the path, heading
                                // at least 135° from it, at least 3 m of path later
    double same_length = 0;     // the same, heading within 45°
    double closing_gap = 0;     // m between the first and last positions
};

RouteStats route_stats(const std::vector<ModelStep>& steps, const BodyCollider& body, const TourParams& params = {});

struct Tour {
    std::vector<Vec2> waypoints;  // closed: the last is the first
    std::vector<ModelStep> steps;
    RouteStats stats;
};

// The tour of `world`'s floor for a body of `radius` and `height` from `start` (none: the free place
// nearest the middle of the largest part of the floor). InputError if the start has no room or the
// tour cannot cover min_coverage of the walkable region.
Tour make_tour(const WorldDescription& world, double radius, double height, std::optional<Vec2> start = std::nullopt,
               const TourParams& tour = {}, const RouteParams& route = {});

}  // namespace bvc3d

#pragma once
// Navigation stage: why a start failed (docs/navigation.md#why-a-start-fails), one class per failed start, from its
// path and what ended it, the yardstick's distance to the goal and the first scale's reward map. Takes: a failed
// start. Gives: its class. The rules, in the order they are tried (the first that holds names it):
//   blocked      it ended wedged (no way open), or its last 20 moves took it less than 0.5 m from where they began
//                and at least half of them touched geometry;
//   closing-in   a cap ended it while its yardstick distance to the goal was still falling: the distance at its end
//                is at least 1 m below the distance where the last quarter of its path (by length) began;
//   plateau      (with a reward map) in the last half of its path, at least 80 % of its positions have a reward
//                (the map's point nearest each) below 1 % of the map's largest for the goal: nothing to climb there;
//   wrong-basin  (with a reward map) climbing the map from the point nearest its end (each time to the highest of the
//                8 neighbours on the map's lattice, while higher) ends on a hill top more than 2 m from the goal;
//   loop         in the last quarter of its path it came back within 0.5 m of a place it had left at least 3 m of
//                path before (it circled);
//   wander       none of these.
#include <span>
#include <string>
#include <vector>

#include "bvc3d/core/geometry.hpp"
#include "bvc3d/navigation/policy.hpp"

namespace bvc3d {

enum class FailureClass { none, blocked, closing_in, plateau, wrong_basin, loop, wander };
// "" (a reached start), blocked, closing-in, plateau, wrong-basin, loop, wander: as starts.csv writes them.
const std::vector<std::string>& failure_class_names();
std::string to_string(FailureClass c);

struct FailedStart {
    StartEnd end = StartEnd::path_cap;
    std::span<const Vec3> path;    // the start, then each move's position
    std::span<const char> bumped;  // per move
    Vec2 goal = Vec2::Zero();
    // The yardstick distance to the goal where the last quarter of the path began, and at its end.
    double distance_at_last_quarter = 0, distance_at_end = 0;
    // The first scale's reward map for this goal: its points (a lattice of `map_cell` m) and values; none in flight.
    std::span<const Vec2> map_points;
    std::span<const double> map_values;
    double map_cell = 0.5;
};

// The index of the path's position where its last `fraction` (by length along it) begins.
std::size_t tail_start(std::span<const Vec3> path, double fraction);
FailureClass classify_failure(const FailedStart& s);

}  // namespace bvc3d

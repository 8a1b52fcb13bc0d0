#pragma once
// Routes (docs/buildings.md#routes): a trajectory through a building that a user does not draw by hand.
// Takes: waypoints on the floor and the ground robot's body (BodyCollider). Gives: the model steps of
// a smooth drive through them, ready to be a trajectory file (trajectory.hpp).
//
// The path is the polyline through the waypoints with each corner rounded by a circular arc: the
// largest radius up to speed²/lateral_acceleration (the arc taken at full speed) that fits between
// the neighboring corners and keeps the body clear of geometry. On an arc of radius R the robot
// drives at most √(lateral_acceleration·R), so |v²/R| never exceeds lateral_acceleration; it speeds
// up and slows down at `acceleration`, starts and ends at rest. A corner where no arc of at least
// `min_turn_radius` fits (a U-turn, a cramped zig-zag) is a stop, a turn in place at `turn_rate`
// (its time counts, no model update: as the random walk's turns) and a start. Heading is the
// direction of motion. One model step per `model_dt` of motion, the first at the start.
#include <string>
#include <vector>

#include "bvc3d/agent/agent.hpp"
#include "bvc3d/agent/body_collider.hpp"
#include "bvc3d/core/params.hpp"

namespace bvc3d {

struct RouteParams {
    double speed = 1.0;                 // m/s, cruising
    double lateral_acceleration = 0.5;  // m/s², at most, in turns
    double acceleration = 0.5;          // m/s², speeding up and slowing down
    double min_turn_radius = 0.1;       // m: tighter corners are turns in place
    double turn_rate = 2.1;             // rad/s, turning in place (the paper's robot)
    double model_dt = 0.288;            // s of motion per model step

    static const params::Table<RouteParams>& table();
    void validate() const { table().check(*this); }
};

// The drive through `waypoints` (at least 2; consecutive equal points are one). InputError naming the
// waypoint that lies inside geometry (closer than the body's radius) or the segment that comes
// closer than that.
std::vector<ModelStep> route_through(const std::vector<Vec2>& waypoints, const BodyCollider& body,
                                     const RouteParams& params = {});

// Waypoints from a text file: one `x y` (or `x,y`) per line, `#` comments, an optional header line
// `x,y`. Errors name the file and the line.
std::vector<Vec2> read_waypoints(const std::string& path);

}  // namespace bvc3d

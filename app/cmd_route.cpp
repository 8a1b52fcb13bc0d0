// bvc3d route: a route through a world from waypoints, or a tour of its floor (docs/buildings.md#routes).
#include <iostream>
#include <memory>
#include <optional>

#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/agent/tour.hpp"
#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "option_groups.hpp"
#include "table_options.hpp"

namespace bvc3d::cli {

namespace {

Vec2 parse_point(const std::string& text, const std::string& what) {
    const auto comma = text.find(',');
    if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos)
        throw InputError(what + " '" + text + "': expected X,Y (meters)");
    return Vec2(parse_number(text.substr(0, comma), what + " x"), parse_number(text.substr(comma + 1), what + " y"));
}

}  // namespace

void add_route_command(CLI::App& app) {
    auto* cmd = app.add_subcommand(
        "route", "Drive a route through a world's floor, from waypoints or as a tour; write it as a trajectory file");
    struct Options {
        WorldOptions world;
        std::string waypoints, start, out;
        bool tour = false;
        TableOptions<RouteParams> route{RouteParams::table()};
        Outputs outputs;
    };
    auto o = std::make_shared<Options>();
    o->world.add_to(*cmd, "", "").front()->required();
    auto* waypoints = cmd->add_option("--waypoints", o->waypoints, "Text file of waypoints, one 'x y' per line (m)");
    auto* tour = cmd->add_flag("--tour", o->tour,
                               "A closed tour of the floor instead: near 90 % of it, part of it driven both ways");
    waypoints->excludes(tour);
    cmd->add_option("--start", o->start, "With --tour: where it starts and ends, X,Y (default: the floor's middle)")
        ->needs(tour);
    static const RouteParams defaults;
    o->route.add_to(*cmd, {"speed", "lateral_acceleration"}, &defaults);
    o->outputs.add(*cmd, "--out", o->out, OutputKind::file, "Trajectory file to write (t,x,y,z,heading rows)")
        ->required();
    cmd->footer(
        "The path joins the waypoints with circular arcs (speed^2/radius never above the lateral acceleration;\n"
        "tight corners are stops and turns in place), heading along the motion, one row per model step (0.288 s)\n"
        "of motion. A waypoint inside geometry, or a segment the robot's body (radius 0.25 m) cannot drive\n"
        "without touching geometry, is refused and named. The file feeds `run --trajectory`, `export-scans`,\n"
        "`localize`, `replay` and Python's TrajectorySpec.");
    cmd->callback([o] {
        if (o->waypoints.empty() == !o->tour) throw InputError("give --waypoints FILE or --tour");
        RouteParams route;
        o->route.apply(route);
        route.validate();
        o->outputs.check();
        const World world(o->world.resolve());
        const RobotParams robot;
        std::vector<ModelStep> steps;
        if (o->tour) {
            std::optional<Vec2> start;
            if (!o->start.empty()) start = parse_point(o->start, "--start");
            const Tour t = make_tour(world.description(), robot.radius, robot.height, start, {}, route);
            steps = t.steps;
            std::cout << "tour of '" << world.name() << "': " << steps.size() << " model steps, " << num(t.stats.length)
                      << " m in " << num(steps.back().t) << " s; passes within 1 m of "
                      << num(std::round(t.stats.coverage * 1000) / 10) << " % of the walkable region ("
                      << num(std::round(t.stats.walkable_area)) << " m2); drives "
                      << num(std::round(t.stats.reverse_length)) << " m again in the opposite direction\n";
        } else {
            const BodyCollider body(world.description(), robot.radius, robot.height);
            steps = route_through(read_waypoints(o->waypoints), body, route);
            std::cout << "route through '" << world.name() << "': " << steps.size() << " model steps in "
                      << num(steps.back().t) << " s\n";
        }
        write_trajectory_file(o->out, steps);
    });
}

}  // namespace bvc3d::cli

// bvc3d route: a route through a world from waypoints, or a tour of its floor (docs/buildings.md#routes).
#include <cmath>
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
#include "python_module.hpp"
#include "table_options.hpp"

namespace bvc3d::cli {

namespace {

Vec2 parse_point(const std::string& text, const std::string& what) {
    const auto comma = text.find(',');
    if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos)
        throw InputError(what + " '" + text + "': expected X,Y (meters)");
    return Vec2(parse_number(text.substr(0, comma), what + " x"), parse_number(text.substr(comma + 1), what + " y"));
}

// A length or a time as people read it: to a tenth.
std::string tenths(double v) { return num(std::round(v * 10) / 10); }

}  // namespace

void add_route_command(CLI::App& app) {
    auto* cmd = app.add_subcommand(
        "route", "Drive a route through a world's floor, from waypoints or as a tour; write it as a trajectory file");
    struct Options {
        WorldOptions world;
        std::string waypoints, start, out, figure;
        bool tour = false;
        int laps = 1;
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
    cmd->add_option("--laps", o->laps,
                    "With --tour: drive it this many times, one lap after the other (a trial that learns on one lap "
                    "and records two can decode the last against the one before)")
        ->capture_default_str()
        ->check(CLI::Range(1, 1000))
        ->needs(tour);
    static const RouteParams defaults;
    o->route.add_to(*cmd, {"speed", "lateral_acceleration"}, &defaults);
    o->outputs.add(*cmd, "--out", o->out, OutputKind::file, "Trajectory file to write (t,x,y,z,heading rows)")
        ->required();
    o->outputs.add(*cmd, "--figure", o->figure, OutputKind::file,
                   "Also draw the route over the world's floor plan at the robot's body height (a .png)");
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
            // The tour ends where it starts: each further lap follows one model step later, from its start.
            const double lap = t.steps.back().t + robot.model_dt;
            for (int k = 1; k < o->laps; ++k)
                for (ModelStep s : t.steps) {
                    s.t += k * lap;
                    steps.push_back(s);
                }
            std::cout << "tour of '" << world.name() << "': " << t.steps.size() << " model steps, "
                      << tenths(t.stats.length) << " m in " << tenths(t.steps.back().t) << " s; passes within 1 m of "
                      << num(std::round(t.stats.coverage * 1000) / 10) << " % of the walkable region ("
                      << num(std::round(t.stats.walkable_area)) << " m2); drives "
                      << num(std::round(t.stats.reverse_length)) << " m again in the opposite direction"
                      << (o->laps > 1 ? "; " + std::to_string(o->laps) + " laps: " + std::to_string(steps.size()) +
                                            " model steps in " + tenths(steps.back().t) + " s"
                                      : "")
                      << "\n";
        } else {
            const BodyCollider body(world.description(), robot.radius, robot.height);
            steps = route_through(read_waypoints(o->waypoints), body, route);
            std::cout << "route through '" << world.name() << "': " << steps.size() << " model steps in "
                      << tenths(steps.back().t) << " s\n";
        }
        write_trajectory_file(o->out, steps);
        // The figure's world is the route's: its source with the world options that were given.
        std::vector<std::string> args{"--world", o->world.world, "--trajectory", o->out, "--out", o->figure};
        if (o->world.tilt) args.insert(args.end(), {"--tilt", num(*o->world.tilt)});
        if (o->world.lean) args.insert(args.end(), {"--lean", *o->world.lean});
        if (o->world.missing_models) args.insert(args.end(), {"--missing-models", *o->world.missing_models});
        if (!o->figure.empty() && run_python_module("bvc3d.route_figure", args).status != 0)
            throw InputError("the figure failed; the route is in '" + o->out + "'; rerun it with:\n  " +
                             python_command().shell_line("bvc3d.route_figure", args));
    });
}

}  // namespace bvc3d::cli

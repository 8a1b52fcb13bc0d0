// bvc3d scan / bvc3d walk: the simulator stage on its own.
#include <cerrno>
#include <cstring>
#include <iostream>
#include <memory>
#include <optional>

#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/csv.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/memory.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "option_groups.hpp"
#include "run_options.hpp"

namespace bvc3d::cli {

namespace {

// Writes CSV rows to --out (atomically) or to standard output.
template <class WriteRows>
void emit(const std::string& out, WriteRows&& write_rows) {
    if (out.empty() || out == "-") {
        CsvWriter csv(std::cout);
        write_rows(csv);
        std::cout.flush();
        if (!std::cout)
            throw InputError(std::string("cannot write to standard output: ") + std::strerror(errno ? errno : EIO));
        return;
    }
    AtomicFile file(out);
    CsvWriter csv(file.stream());
    write_rows(csv);
    file.commit();
}

const char* const csv_out_help = "CSV file to write (default: standard output)";

void add_scan(CLI::App& app) {
    auto* cmd = app.add_subcommand("scan", "Cast one LiDAR scan and write one row per hit: range, azimuth, elevation");
    struct Options {
        WorldOptions world;
        std::string sensor = "spherical", pose, out;
        Outputs outputs;
    };
    auto o = std::make_shared<Options>();
    o->world.add_to(*cmd);
    add_sensor_option(*cmd, o->sensor);
    cmd->add_option("--pose", o->pose, "Robot pose X,Y,HEADING (m, m, rad; or e.g. 90deg)")->required();
    o->outputs.add(*cmd, "--out", o->out, OutputKind::file, csv_out_help);
    cmd->footer(
        "Ranges in meters from the sensor; azimuth is allocentric (0 = +x, counter-clockwise) and elevation\n"
        "positive up, both in radians. Beams with no hit within max_range are left out.");
    cmd->callback([o] {
        o->outputs.check();
        const World w(o->world.resolve());
        const Lidar lidar(config::resolve_sensor(o->sensor));
        const Pose p = parse_pose(o->pose);
        warn_if_blocked(w, p);
        const Scan scan = lidar.scan(w, p);
        emit(o->out, [&](CsvWriter& csv) {
            csv.row("range", "azimuth", "elevation");
            for (const auto& r : scan) csv.row(r.range, r.azimuth, r.elevation);
        });
    });
}

void add_walk(CLI::App& app) {
    auto* cmd =
        app.add_subcommand("walk", "Run the seeded random walk and write its model steps: t, x, y, heading, bumped");
    struct Options {
        WorldOptions world;
        double hours = 1.0;
        std::uint64_t seed = 0;
        std::string out;
        bool no_memory_check = false;
        Outputs outputs;
    };
    auto o = std::make_shared<Options>();
    o->world.add_to(*cmd);
    cmd->add_option("--hours", o->hours, "Simulated hours to walk")->capture_default_str()->check(non_negative_check);
    cmd->add_option("--seed", o->seed, "Random seed, 0 .. 2^64 - 1")->capture_default_str()->check(seed_check);
    o->outputs.add(*cmd, "--out", o->out, OutputKind::file, csv_out_help);
    cmd->add_flag("--no-memory-check", o->no_memory_check, no_memory_check_help);
    cmd->footer(
        "One row per model step: t in simulated seconds, position in meters, heading in radians,\n"
        "bumped = 1 when the step ended against an obstacle.");
    cmd->callback([o] {
        if (o->hours > max_agent_hours)
            throw InputError("--hours " + num(o->hours) + " is more than the limit of " + num(max_agent_hours) +
                             " simulated hours");
        if (!o->no_memory_check)  // the steps are held in memory, one ModelStep each
            check_memory(o->hours * 3600.0 / RobotParams{}.model_dt * sizeof(ModelStep),
                         "walk --hours " + num(o->hours), "walk fewer hours, or pass --no-memory-check to try anyway");
        o->outputs.check();
        const World w(o->world.resolve());
        const auto steps = random_walk(w, o->hours, o->seed);
        emit(o->out, [&](CsvWriter& csv) {
            csv.row("t", "x", "y", "heading", "bumped");
            for (const auto& s : steps) csv.row(s.t, s.pose.x, s.pose.y, s.pose.heading, s.bumped);
        });
    });
}

}  // namespace

void add_simulator_commands(CLI::App& app) {
    add_scan(app);
    add_walk(app);
}

}  // namespace bvc3d::cli

// bvc3d scan / bvc3d walk: the simulator stage on its own.
#include <cerrno>
#include <cstring>
#include <iostream>
#include <memory>
#include <optional>

#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/memory.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "run_options.hpp"

namespace bvc3d::cli {

namespace {

struct WorldOptions {
    std::string world = "cross";
    std::optional<double> tilt;
    std::string lean = "+x+y";

    void add_to(CLI::App& cmd) {
        cmd.add_option("--world", world, "Preset (cross, cross-0, cross-30, cross-45, cross-60) or a world YAML file")
            ->capture_default_str();
        cmd.add_option("--tilt", tilt, "Tilt of the cross arena's central walls in degrees (with --world cross)");
        cmd.add_option("--lean", lean, "Corner the cross walls lean toward: +x+y, +x-y, -x+y, -x-y")
            ->capture_default_str();
    }
    World make() const { return World(config::resolve_world(world, tilt, lean)); }
};

// Writes rows to --out (atomically) or to standard output.
template <class WriteRows>
void emit(const std::string& out, const std::string& header, WriteRows&& write_rows) {
    if (out.empty() || out == "-") {
        std::cout << header << "\n";
        write_rows(std::cout);
        std::cout.flush();
        if (!std::cout)
            throw InputError(std::string("cannot write to standard output: ") + std::strerror(errno ? errno : EIO));
        return;
    }
    AtomicFile file(out);
    file.stream() << header << "\n";
    write_rows(file.stream());
    file.commit();
}

void add_scan(CLI::App& app) {
    auto* cmd = app.add_subcommand("scan", "Cast one LiDAR scan and write one row per hit: range, azimuth, elevation");
    auto world = std::make_shared<WorldOptions>();
    auto sensor = std::make_shared<std::string>("spherical");
    auto pose = std::make_shared<std::string>();
    auto out = std::make_shared<std::string>();
    world->add_to(*cmd);
    cmd->add_option("--sensor", *sensor, "horizontal, spherical, or a sensor YAML file")->capture_default_str();
    cmd->add_option("--pose", *pose, "Robot pose X,Y,HEADING (m, m, rad; or e.g. 90deg)")->required();
    cmd->add_option("--out", *out, "CSV file to write (default: standard output)")->transform(output_path);
    cmd->footer(
        "Ranges in meters from the sensor; azimuth is allocentric (0 = +x, counter-clockwise) and elevation\n"
        "positive up, both in radians. Beams with no hit within max_range are left out.");
    cmd->callback([=] {
        const World w = world->make();
        const Lidar lidar(config::resolve_sensor(*sensor));
        const Pose p = parse_pose(*pose);
        if (!out->empty() && *out != "-") require_not_directory(*out, "--out");
        warn_if_blocked(w, p);
        const Scan scan = lidar.scan(w, p);
        emit(*out, "range,azimuth,elevation", [&](std::ostream& os) {
            for (const auto& r : scan) os << num(r.range) << ',' << num(r.azimuth) << ',' << num(r.elevation) << '\n';
        });
    });
}

void add_walk(CLI::App& app) {
    auto* cmd =
        app.add_subcommand("walk", "Run the seeded random walk and write its model steps: t, x, y, heading, bumped");
    auto world = std::make_shared<WorldOptions>();
    auto hours = std::make_shared<double>(1.0);
    auto seed = std::make_shared<std::uint64_t>(0);
    auto out = std::make_shared<std::string>();
    auto no_memory_check = std::make_shared<bool>(false);
    world->add_to(*cmd);
    cmd->add_option("--hours", *hours, "Simulated hours to walk")->capture_default_str()->check(non_negative_check);
    cmd->add_option("--seed", *seed, "Random seed, 0 .. 2^64 - 1")->capture_default_str()->check(seed_check);
    cmd->add_option("--out", *out, "CSV file to write (default: standard output)")->transform(output_path);
    cmd->add_flag("--no-memory-check", *no_memory_check, no_memory_check_help);
    cmd->footer(
        "One row per model step: t in simulated seconds, position in meters, heading in radians,\n"
        "bumped = 1 when the step ended against an obstacle.");
    cmd->callback([=] {
        if (*hours > max_agent_hours)
            throw InputError("--hours " + num(*hours) + " is more than the limit of " + num(max_agent_hours) +
                             " simulated hours");
        if (!*no_memory_check)  // the steps are held in memory, one ModelStep each
            check_memory(*hours * 3600.0 / RobotParams{}.model_dt * sizeof(ModelStep), "walk --hours " + num(*hours),
                         "walk fewer hours, or pass --no-memory-check to try anyway");
        if (!out->empty() && *out != "-") require_not_directory(*out, "--out");
        const World w = world->make();
        const auto steps = random_walk(w, *hours, *seed);
        emit(*out, "t,x,y,heading,bumped", [&](std::ostream& os) {
            for (const auto& s : steps)
                os << num(s.t) << ',' << num(s.pose.x) << ',' << num(s.pose.y) << ',' << num(s.pose.heading) << ','
                   << (s.bumped ? 1 : 0) << '\n';
        });
    });
}

}  // namespace

void add_simulator_commands(CLI::App& app) {
    add_scan(app);
    add_walk(app);
}

}  // namespace bvc3d::cli

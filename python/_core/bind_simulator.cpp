// World, Sensor, agents (random walk, trajectories).
#include "bindings.hpp"

#include "bvc3d/agent/flying_walk.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/config/world_yaml.hpp"

namespace bvc3d::py {

namespace {

LidarSpec sensor_of(const pyb::object& sensor) {
    if (pyb::isinstance<pyb::str>(sensor)) return config::resolve_sensor(sensor.cast<std::string>());
    return sensor.cast<LidarSpec>();
}

pyb::array_t<double> scan_to_numpy(const Scan& s) {
    static_assert(sizeof(LidarReturn) == 3 * sizeof(double));
    return to_numpy(reinterpret_cast<const double*>(s.data()), {static_cast<pyb::ssize_t>(s.size()), 3});
}

// Model steps as a dict of arrays t, x, y, z, heading, bumped.
pyb::dict steps_to_dict(const std::vector<ModelStep>& steps) {
    const auto n = static_cast<pyb::ssize_t>(steps.size());
    pyb::array_t<double> t(n), x(n), y(n), z(n), h(n);
    pyb::array_t<bool> bumped(n);
    for (pyb::ssize_t i = 0; i < n; ++i) {
        const auto& s = steps[static_cast<std::size_t>(i)];
        t.mutable_at(i) = s.t;
        x.mutable_at(i) = s.pose.x;
        y.mutable_at(i) = s.pose.y;
        z.mutable_at(i) = s.pose.z;
        h.mutable_at(i) = s.pose.heading;
        bumped.mutable_at(i) = s.bumped;
    }
    pyb::dict d;
    d["t"] = t;
    d["x"] = x;
    d["y"] = y;
    d["z"] = z;
    d["heading"] = h;
    d["bumped"] = bumped;
    return d;
}

void bind_sensor(pyb::module_& m) {
    auto cls = pyb::class_<LidarSpec>(m, "Sensor",
                                      (R"doc(
A range scanner: a table of beam elevations (rows) × azimuth_count columns (docs/worlds.md#sensors).
Sensor.horizontal() and Sensor.spherical() are the paper's two scanners; Sensor(**keys) any other:
)doc" + describe(LidarSpec::table(), LidarSpec{}))
                                          .c_str());
    cls.def(pyb::init([](const pyb::args& args, const pyb::kwargs& kwargs) {
           LidarSpec s;
           s.name = "custom";
           apply_args(s, LidarSpec::table(), args, kwargs);
           return s;
       }))
        .def_static("horizontal", &LidarSpec::horizontal, "The paper's 2-D scanner: 720 beams at 0.08 m")
        .def_static("spherical", &LidarSpec::spherical, pyb::arg("upper_only") = true,
                    "The paper's 90×180 range image at 0.18 m; upper_only keeps rows 0-44 (elevation > 0)")
        .def_static(
            "spherical_as_authors", &LidarSpec::spherical_as_authors, pyb::arg("upper_only") = true,
            "The spherical image labeled as the authors' code labels it (angle labels, whole-column heading roll)")
        .def_static("from_yaml", &config::resolve_sensor, pyb::arg("path"))
        .def_property_readonly("beam_count", &LidarSpec::beam_count)
        .def("__repr__", [](const LidarSpec& s) {
            return "Sensor('" + s.name + "', rows=" + std::to_string(s.elevations.size()) +
                   ", azimuth_count=" + std::to_string(s.azimuth_count) + ")";
        });
    def_fields<LidarSpec>(cls);
}

void bind_world(pyb::module_& m) {
    pyb::class_<World>(m, "World",
                       "A 3-D world: triangles, a walkable floor region and a start region (docs/worlds.md)")
        .def_static(
            "cross",
            [](double tilt_deg, const std::string& lean) {
                CrossArenaParams p;
                p.tilt_deg = tilt_deg;
                p.lean = lean;
                return World::cross(p);
            },
            pyb::arg("tilt_deg") = CrossArenaParams{}.tilt_deg, pyb::arg("lean") = CrossArenaParams{}.lean,
            "The paper's cross arena")
        .def_static(
            "from_yaml",
            [](const std::filesystem::path& path) { return World(config::load_world_file(path.string())); },
            pyb::arg("path"))
        .def_static(
            "from_yaml_text",
            [](const std::string& text, const std::string& name) {
                return World(config::world_from_yaml(config::YamlView::load_string(text, name)));
            },
            pyb::arg("text"), pyb::arg("name") = "<python>",
            "A world from the text of a world YAML (docs/worlds.md); errors name `name` and the key")
        .def_static(
            "preset",
            [](const std::string& name, std::optional<double> tilt_deg) {
                return World(config::resolve_world(name, tilt_deg));
            },
            pyb::arg("name"), pyb::arg("tilt_deg") = pyb::none(),
            "A preset name (cross, cross-30, ..., cross-webots, flight-room, atrium) or a world YAML file; tilt_deg "
            "for cross and cross-webots")
        .def_property_readonly("name", &World::name)
        .def_property_readonly(
            "triangles",
            [](const World& w) {
                const auto& mesh = w.mesh();
                pyb::array_t<double> a({static_cast<pyb::ssize_t>(mesh.size()), pyb::ssize_t{3}, pyb::ssize_t{3}});
                auto v = a.mutable_unchecked<3>();
                for (std::size_t t = 0; t < mesh.size(); ++t) {
                    const auto c = mesh.corners(t);
                    for (int i = 0; i < 3; ++i)
                        for (int k = 0; k < 3; ++k) v(t, i, k) = c[i][k];
                }
                return a;
            },
            "(T, 3, 3) array of triangle corners")
        .def_property_readonly(
            "walkable",
            [](const World& w) {
                const auto& p = w.description().walkable.points;
                std::vector<double> flat;
                for (const auto& q : p) flat.insert(flat.end(), {q.x(), q.y()});
                return to_numpy(flat.data(), {static_cast<pyb::ssize_t>(p.size()), 2});
            },
            "(K, 2) polygon the robot's body stays inside (empty in a flight-only world)")
        .def_property_readonly(
            "flight_volume",
            [](const World& w) -> pyb::object {
                const auto& f = w.description().flight;
                if (!f) return pyb::none();
                std::vector<double> flat;
                for (const auto& q : f->region.points) flat.insert(flat.end(), {q.x(), q.y()});
                pyb::dict d;
                d["region"] = to_numpy(flat.data(), {static_cast<pyb::ssize_t>(f->region.points.size()), 2});
                d["z_min"] = f->z_min;
                d["z_max"] = f->z_max;
                return d;
            },
            "The flight volume as a dict (region (K, 2) polygon, z_min, z_max), or None for a ground-only world")
        .def(
            "scan",
            [](const World& w, const pyb::object& sensor, double x, double y, double heading,
               const pyb::object& noise_seed, const pyb::object& scan_index, double z, double pitch, double roll) {
                const Lidar lidar(sensor_of(sensor));
                const NoiseKey key{seed_of(noise_seed, "noise_seed"), seed_of(scan_index, "scan_index")};
                Scan s;
                {
                    pyb::gil_scoped_release release;
                    lidar.scan(w, Pose{x, y, z, heading, pitch, roll}, s, key);
                }
                return scan_to_numpy(s);
            },
            pyb::arg("sensor"), pyb::arg("x"), pyb::arg("y"), pyb::arg("heading"), pyb::arg("noise_seed") = 0,
            pyb::arg("scan_index") = 0, pyb::arg("z") = 0.0, pyb::arg("pitch") = 0.0, pyb::arg("roll") = 0.0,
            R"doc(Cast a scan from the pose (x, y, z; heading, pitch, roll in rad). z is the agent's base above the
floor; the sensor sits its own height above it and tilts with pitch (nose up) and roll. sensor:
"horizontal", "spherical" or a Sensor. Returns a float64 (N, 3) array: range [m], allocentric azimuth
[rad], elevation [rad], both in the world frame.)doc");
}

}  // namespace

void bind_simulator(pyb::module_& m) {
    bind_sensor(m);
    bind_world(m);
    m.def(
        "random_walk",
        [](const World& w, double hours, const pyb::object& seed, const pyb::kwargs& robot) {
            const std::uint64_t s = seed_of(seed, "seed");
            RobotParams p;
            apply_kwargs(p, RobotParams::table(), robot);
            const auto steps = interruptible([&](const std::atomic<bool>&) { return random_walk(w, hours, s, p); });
            return steps_to_dict(steps);
        },
        pyb::arg("world"), pyb::arg("hours"), pyb::arg("seed"),
        ("The random walk: dict of arrays t, x, y, z, heading, bumped, one entry per model step (x, y, heading\n"
         "where the model sees the world from). Robot keywords and their defaults (the paper's robot):\n" +
         describe(RobotParams::table(), RobotParams{}))
            .c_str());
    m.def(
        "flying_walk",
        [](const World& w, double hours, std::uint64_t seed, const pyb::kwargs& kwargs) {
            FlightParams params;
            apply_kwargs(params, FlightParams::table(), kwargs);
            std::vector<ModelStep> steps;
            {
                pyb::gil_scoped_release release;
                steps = flying_walk(w, hours, seed, params);
            }
            return steps_to_dict(steps);
        },
        pyb::arg("world"), pyb::arg("hours"), pyb::arg("seed"),
        (R"doc(The flying agent's 3-D random walk (docs/flying.md): dict of arrays t, x, y, z (the body's center),
heading (the yaw of flight), bumped, one entry per model step. The world needs a flight volume
(flight-room, atrium, the cross arenas, or flight_volume in a world YAML). Flight keywords and
their defaults:
)doc" + describe(FlightParams::table(), FlightParams{}))
            .c_str());
    m.def(
        "read_trajectory", [](const std::filesystem::path& path) { return steps_to_dict(read_trajectory_file(path)); },
        pyb::arg("path"),
        R"doc(A trajectory file (rows t, x, y, [z], heading; docs/experiments.md#user-trajectories) as a dict of
arrays t (shifted to start at 0), x, y, z, heading, bumped.)doc");
}

}  // namespace bvc3d::py

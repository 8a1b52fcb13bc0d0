// World, Sensor, agents (random walk, trajectories).
#include "bindings.hpp"

#include "bvc3d/agent/body_collider.hpp"
#include "bvc3d/agent/flying_walk.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/config/building.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/world/gazebo_world.hpp"

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

// A Gazebo world's file given to the YAML reader: say which loader reads it (not what YAML makes of XML).
void refuse_gazebo_file(const std::filesystem::path& path) {
    if (is_gazebo_file(path.string()))
        throw InputError("'" + path.string() + "' is a Gazebo world (" + path.extension().string() +
                         "): read it with World.from_sdf (or World.preset, which reads any world file)");
}

void bind_world(pyb::module_& m) {
    pyb::class_<World>(m, "World", pyb::dynamic_attr(),
                       "A 3-D world: triangles, a walkable floor region and a start region (docs/worlds.md)")
        .def_static(
            "cross",
            [](double tilt_deg, const std::string& lean) {
                CrossArenaParams p;
                p.tilt_deg = tilt_deg;
                p.lean = lean;
                return with_source(World::cross(p), WorldSpec{"cross", tilt_deg, lean});
            },
            pyb::arg("tilt_deg") = CrossArenaParams{}.tilt_deg, pyb::arg("lean") = CrossArenaParams{}.lean,
            "The paper's cross arena")
        .def_static(
            "from_yaml",
            [](const std::filesystem::path& path) {
                refuse_gazebo_file(path);
                return with_source(World(config::load_world_file(path.string())),
                                   WorldSpec{path.string(), std::nullopt, "+x+y"});
            },
            pyb::arg("path"), "A world YAML file (docs/worlds.md); a Gazebo world is World.from_sdf's")
        .def_static(
            "from_yaml_text",
            [](const std::string& text, const std::string& name) {
                return World(config::world_from_yaml(config::YamlView::load_string(text, name)));
            },
            pyb::arg("text"), pyb::arg("name") = "<python>",
            "A world from the text of a world YAML (docs/worlds.md); errors name `name` and the key")
        .def_static(
            "preset",
            [](const std::filesystem::path& name, std::optional<double> tilt_deg, const std::string& lean,
               const std::string& missing_models) {
                config::MissingModels missing{};
                try {
                    missing = config::parse_missing_models(missing_models);
                } catch (const InputError& e) {
                    throw InputError(std::string("missing_models ") + e.what());
                }
                return with_source(World(config::resolve_world(name.string(), tilt_deg, lean, missing)),
                                   WorldSpec{name.string(), tilt_deg, lean, missing});
            },
            pyb::arg("name"), pyb::arg("tilt_deg") = pyb::none(), pyb::arg("lean") = CrossArenaParams{}.lean,
            pyb::arg("missing_models") = "error",
            "A preset name (cross, cross-30, ..., cross-webots, flight-room, atrium) or a world file (YAML, Gazebo "
            ".world or .sdf); tilt_deg and lean for cross and cross-webots; missing_models 'skip' builds a Gazebo "
            "world without the included models that are not found (World.left_out names them), 'error' refuses it")
        .def_property_readonly("name", &World::name)
        .def(
            "floor_plan",
            [](const World& w, double height) {
                const BodyCollider body(w.description(), RobotParams{}.radius, height);
                std::vector<double> ends, radii;
                for (const auto& s : body.segments()) {
                    ends.insert(ends.end(), {s.a.x(), s.a.y(), s.b.x(), s.b.y()});
                    radii.push_back(s.radius);
                }
                const auto n = static_cast<pyb::ssize_t>(radii.size());
                pyb::dict d;
                d["segments"] = to_numpy(ends.data(), {n, 2, 2});
                d["radii"] = to_numpy(radii.data(), {n});
                return d;
            },
            pyb::arg("height") = RobotParams{}.height,
            R"doc(The floor plan the ground robot's body meets, cut at its height (default the paper's robot, 0.1 m):
what its collision reads (docs/worlds.md). A dict: segments (S, 2, 2), the outline of every surface between
the floor (or the world's step height) and `height`, the walkable region's edge and the drop edges; radii
(S,), 0 for a segment, a sphere's cut for a point cloud's point (its disc: a == b).)doc")
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

// The source a World was made from, as an attribute of its Python object.
constexpr const char* source_attribute = "_bvc3d_source";

pyb::object with_source(World world, const WorldSpec& source) {
    pyb::object obj = pyb::cast(std::move(world));
    obj.attr(source_attribute) = pyb::make_tuple(source.source, source.tilt_deg, source.lean);
    return obj;
}

namespace {
bool is_path(const pyb::handle& obj) { return pyb::isinstance<pyb::str>(obj) || pyb::hasattr(obj, "__fspath__"); }
std::string path_text(const pyb::handle& obj) {
    return pyb::str(pyb::module_::import("os").attr("fspath")(obj)).cast<std::string>();
}
const char* const world_kinds = "a World, a preset name or a world file's path";
}  // namespace

std::shared_ptr<const World> world_of(const pyb::handle& obj, const std::string& key) {
    if (pyb::isinstance<World>(obj))
        return std::shared_ptr<const World>(std::shared_ptr<const World>{}, &obj.cast<const World&>());
    if (is_path(obj)) return std::make_shared<const World>(config::resolve_world(path_text(obj)));
    throw InputError(key + " must be " + world_kinds + ", not " + type_name(obj));
}

WorldSpec world_source_of(const pyb::handle& obj, const std::string& key) {
    if (is_path(obj)) return WorldSpec{path_text(obj), std::nullopt, "+x+y"};
    if (!pyb::isinstance<World>(obj)) throw InputError(key + " must be " + world_kinds + ", not " + type_name(obj));
    if (!pyb::hasattr(obj, source_attribute))
        throw InputError(key +
                         ": this World was built in Python (from_dict, from_triangles, from_yaml_text, or "
                         "from_sdf with options), and what runs here records where its world came from: give "
                         "a preset name or a world file (a world YAML can say how to read a Gazebo world)");
    const auto t = obj.attr(source_attribute).cast<pyb::tuple>();
    return WorldSpec{t[0].cast<std::string>(), t[1].cast<std::optional<double>>(), t[2].cast<std::string>()};
}

void bind_simulator(pyb::module_& m) {
    bind_sensor(m);
    bind_world(m);
    m.def(
        "random_walk",
        [](const pyb::object& world, double hours, const pyb::object& seed, const pyb::kwargs& robot) {
            const auto w = world_of(world, "random_walk: world");
            const std::uint64_t s = seed_of(seed, "seed");
            RobotParams p;
            apply_kwargs(p, RobotParams::table(), robot);
            const auto steps = interruptible([&](const std::atomic<bool>&) { return random_walk(*w, hours, s, p); });
            return steps_to_dict(steps);
        },
        pyb::arg("world"), pyb::arg("hours"), pyb::arg("seed"),
        ("The random walk: dict of arrays t, x, y, z, heading, bumped, one entry per model step (x, y, heading\n"
         "where the model sees the world from). Robot keywords and their defaults (the paper's robot):\n" +
         describe(RobotParams::table(), RobotParams{}))
            .c_str());
    m.def(
        "flying_walk",
        [](const pyb::object& world, double hours, std::uint64_t seed, const pyb::kwargs& kwargs) {
            const auto w = world_of(world, "flying_walk: world");
            FlightParams params;
            apply_kwargs(params, FlightParams::table(), kwargs);
            std::vector<ModelStep> steps;
            {
                pyb::gil_scoped_release release;
                steps = flying_walk(*w, hours, seed, params);
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

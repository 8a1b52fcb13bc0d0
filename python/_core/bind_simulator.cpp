// World, Sensor and random walk.
#include "bindings.hpp"

#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/robot/random_walk.hpp"

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

}  // namespace

void bind_simulator(pyb::module_& m) {
    pyb::class_<LidarSpec>(m, "Sensor", R"doc(
A range scanner: a table of beam elevations (rows) × azimuth_count columns (SPEC §3).
Use Sensor.horizontal() or Sensor.spherical() for the paper's two scanners.)doc")
        .def(pyb::init([](std::vector<double> elevations, int azimuth_count, double height, double max_range,
                          double range_noise_sd, double dropout, double azimuth_offset, std::string name) {
                 LidarSpec s;
                 s.elevations = std::move(elevations);
                 s.azimuth_count = azimuth_count;
                 s.height = height;
                 s.max_range = max_range;
                 s.range_noise_sd = range_noise_sd;
                 s.dropout = dropout;
                 s.azimuth_offset = azimuth_offset;
                 s.name = std::move(name);
                 s.validate();
                 return s;
             }),
             pyb::arg("elevations"), pyb::arg("azimuth_count"), pyb::arg("height") = 0.18,
             pyb::arg("max_range") = 20.0, pyb::arg("range_noise_sd") = 0.0, pyb::arg("dropout") = 0.0,
             pyb::arg("azimuth_offset") = 0.0, pyb::arg("name") = "custom",
             "elevations in radians (rows, top first); azimuth_offset in radians")
        .def_static("horizontal", &LidarSpec::horizontal, "The paper's 2-D scanner: 720 beams at 0.08 m")
        .def_static("spherical", &LidarSpec::spherical, pyb::arg("upper_only") = true,
                    "The paper's 90×180 range image at 0.18 m; upper_only keeps rows 0-44 (elevation > 0)")
        .def_static("from_yaml", &config::resolve_sensor, pyb::arg("path"))
        .def_readwrite("name", &LidarSpec::name)
        .def_readwrite("elevations", &LidarSpec::elevations)
        .def_readwrite("azimuth_count", &LidarSpec::azimuth_count)
        .def_readwrite("azimuth_offset", &LidarSpec::azimuth_offset)
        .def_readwrite("height", &LidarSpec::height)
        .def_readwrite("max_range", &LidarSpec::max_range)
        .def_readwrite("range_noise_sd", &LidarSpec::range_noise_sd)
        .def_readwrite("dropout", &LidarSpec::dropout)
        .def_property_readonly("beam_count", &LidarSpec::beam_count)
        .def("__repr__", [](const LidarSpec& s) {
            return "Sensor('" + s.name + "', rows=" + std::to_string(s.elevations.size()) +
                   ", azimuth_count=" + std::to_string(s.azimuth_count) + ")";
        });

    pyb::class_<World>(m, "World", "A 3-D world: triangles, a walkable floor region and a start region (SPEC §2)")
        .def_static(
            "cross",
            [](double tilt_deg, const std::string& lean) {
                CrossArenaParams p;
                p.tilt_deg = tilt_deg;
                p.lean = lean;
                return World::cross(p);
            },
            pyb::arg("tilt_deg") = 0.0, pyb::arg("lean") = "+x+y", "The paper's cross arena (SPEC §2.1)")
        .def_static(
            "from_yaml", [](const std::string& path) { return World(config::load_world_file(path)); },
            pyb::arg("path"))
        .def_static(
            "preset", [](const std::string& name) { return World(config::resolve_world(name)); },
            pyb::arg("name"), "A preset name (cross, cross-30, ...) or a world YAML file")
        .def_property_readonly("name", &World::name)
        .def_property_readonly("triangles",
                               [](const World& w) {
                                   const auto& mesh = w.mesh();
                                   pyb::array_t<double> a({static_cast<pyb::ssize_t>(mesh.size()), pyb::ssize_t{3},
                                                           pyb::ssize_t{3}});
                                   auto v = a.mutable_unchecked<3>();
                                   for (std::size_t t = 0; t < mesh.size(); ++t) {
                                       const auto c = mesh.corners(t);
                                       for (int i = 0; i < 3; ++i)
                                           for (int k = 0; k < 3; ++k) v(t, i, k) = c[i][k];
                                   }
                                   return a;
                               },
                               "(T, 3, 3) array of triangle corners")
        .def_property_readonly("walkable",
                               [](const World& w) {
                                   const auto& p = w.description().walkable.points;
                                   std::vector<double> flat;
                                   for (const auto& q : p) flat.insert(flat.end(), {q.x(), q.y()});
                                   return to_numpy(flat.data(), {static_cast<pyb::ssize_t>(p.size()), 2});
                               },
                               "(K, 2) polygon the robot's body stays inside")
        .def(
            "scan",
            [](const World& w, const pyb::object& sensor, double x, double y, double heading,
               std::uint64_t noise_seed, std::uint64_t scan_index) {
                const Lidar lidar(sensor_of(sensor));
                Scan s;
                {
                    pyb::gil_scoped_release release;
                    lidar.scan(w, Pose{x, y, heading}, s, NoiseKey{noise_seed, scan_index});
                }
                return scan_to_numpy(s);
            },
            pyb::arg("sensor"), pyb::arg("x"), pyb::arg("y"), pyb::arg("heading"), pyb::arg("noise_seed") = 0,
            pyb::arg("scan_index") = 0,
            R"doc(Cast a scan from pose (x, y, heading [rad]). sensor: "horizontal", "spherical" or a Sensor.
Returns a float64 (N, 3) array: range [m], allocentric azimuth [rad], elevation [rad].)doc");

    m.def(
        "random_walk",
        [](const World& w, double hours, std::uint64_t seed) {
            std::vector<WalkStep> steps;
            {
                pyb::gil_scoped_release release;
                steps = random_walk(w, hours, seed);
            }
            const auto n = static_cast<pyb::ssize_t>(steps.size());
            pyb::array_t<double> t(n), x(n), y(n), h(n);
            pyb::array_t<bool> bumped(n);
            for (pyb::ssize_t i = 0; i < n; ++i) {
                t.mutable_at(i) = steps[i].t;
                x.mutable_at(i) = steps[i].x;
                y.mutable_at(i) = steps[i].y;
                h.mutable_at(i) = steps[i].heading;
                bumped.mutable_at(i) = steps[i].bumped;
            }
            pyb::dict d;
            d["t"] = t;
            d["x"] = x;
            d["y"] = y;
            d["heading"] = h;
            d["bumped"] = bumped;
            return d;
        },
        pyb::arg("world"), pyb::arg("hours"), pyb::arg("seed"),
        "The paper's random walk (SPEC §4): dict of arrays t, x, y, heading, bumped, one entry per model step");
}

}  // namespace bvc3d::py

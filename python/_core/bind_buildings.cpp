// Buildings (docs/buildings.md): Gazebo worlds, the real LiDAR models, routes and tours.
#include "bindings.hpp"

#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/agent/tour.hpp"
#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/config/building.hpp"
#include "bvc3d/sensor/lidar_models.hpp"

namespace bvc3d::py {

namespace {

pyb::dict steps_dict(const std::vector<ModelStep>& steps) {
    const auto n = static_cast<pyb::ssize_t>(steps.size());
    pyb::array_t<double> t(n), x(n), y(n), z(n), h(n);
    for (pyb::ssize_t i = 0; i < n; ++i) {
        const auto& s = steps[static_cast<std::size_t>(i)];
        t.mutable_at(i) = s.t;
        x.mutable_at(i) = s.pose.x;
        y.mutable_at(i) = s.pose.y;
        z.mutable_at(i) = s.pose.z;
        h.mutable_at(i) = s.pose.heading;
    }
    pyb::dict d;
    d["t"] = t;
    d["x"] = x;
    d["y"] = y;
    d["z"] = z;
    d["heading"] = h;
    return d;
}

std::vector<Vec2> points_of(const pyb::handle& obj, const std::string& name) {
    const auto a = real_array(obj, name);
    if (a.ndim() != 2 || a.shape(1) != 2) throw InputError(name + " must be an (N, 2) array of x, y");
    std::vector<Vec2> out;
    for (pyb::ssize_t i = 0; i < a.shape(0); ++i) out.emplace_back(a.at(i, 0), a.at(i, 1));
    return out;
}

pyb::dict stats_dict(const RouteStats& s) {
    pyb::dict d;
    d["length"] = s.length;
    d["coverage"] = s.coverage;
    d["walkable_area"] = s.walkable_area;
    d["reverse_length"] = s.reverse_length;
    d["same_length"] = s.same_length;
    d["closing_gap"] = s.closing_gap;
    return d;
}

// Keyword arguments split between two parameter tables.
template <class A, class B>
void apply_split(A& a, B& b, const pyb::kwargs& kwargs) {
    pyb::kwargs ka, kb;
    for (const auto& [k, v] : kwargs) {
        const std::string key = pyb::str(k);
        if (A::table().find(key)) ka[k] = v;
        else kb[k] = v;
    }
    apply_kwargs(a, A::table(), ka);
    apply_kwargs(b, B::table(), kb);
}

}  // namespace

void bind_buildings(pyb::module_& m) {
    auto world = pyb::reinterpret_borrow<pyb::class_<World>>(m.attr("World"));
    world
        .def_static(
            "from_sdf",
            [](const std::filesystem::path& path, const std::vector<std::string>& model_path,
               const std::string& geometry, std::optional<double> floor_z, const std::string& missing_models,
               bool flight_volume, const std::string& name, const std::vector<std::string>& resource_path) {
                config::BuildingSpec spec;
                spec.file = path.string();
                spec.name = name;
                spec.gazebo.model_path = model_path;
                spec.gazebo.resource_path = resource_path;
                if (geometry != "visual" && geometry != "collision")
                    throw InputError("geometry must be 'visual' or 'collision', got '" + geometry + "'");
                spec.gazebo.geometry =
                    geometry == "visual" ? GazeboOptions::Geometry::visual : GazeboOptions::Geometry::collision;
                if (missing_models != "error" && missing_models != "skip")
                    throw InputError("missing_models must be 'error' or 'skip', got '" + missing_models + "'");
                spec.gazebo.skip_missing_models = missing_models == "skip";
                spec.floor_z = floor_z;
                if (flight_volume) spec.flight = config::StoreyFlight{};
                pyb::gil_scoped_release release;
                return World(config::building_world(spec));
            },
            pyb::arg("path"), pyb::arg("model_path") = std::vector<std::string>{}, pyb::arg("geometry") = "visual",
            pyb::arg("floor_z") = pyb::none(), pyb::arg("missing_models") = "error", pyb::arg("flight_volume") = false,
            pyb::arg("name") = "", pyb::arg("resource_path") = std::vector<std::string>{},
            R"doc(A Gazebo (SDF) world (docs/buildings.md): model_path lists folders searched for model://NAME before
the `models` folder beside the world's folder and GAZEBO_MODEL_PATH; resource_path folders searched for relative
file:// meshes before GAZEBO_RESOURCE_PATH; geometry 'visual' or 'collision'; floor_z the
height of the floor to walk on (default the lowest); missing_models 'error' or 'skip'; flight_volume=True: a
flight volume filling the storey. The chosen floor is moved to z = 0 (World.floor_z says by how much).)doc")
        .def_property_readonly(
            "parts",
            [](const World& w) {
                pyb::list parts;
                for (const auto& p : w.description().parts) {
                    pyb::dict d;
                    d["name"] = p.name;
                    d["shape"] = p.shape;
                    d["file"] = p.file;
                    d["first_triangle"] = p.first_triangle;
                    d["triangle_count"] = p.triangle_count;
                    d["sphere_set"] = p.sphere_set;
                    d["sphere_index"] = p.sphere_index;
                    parts.append(d);
                }
                return parts;
            },
            "Named pieces of the geometry (a Gazebo world's visuals or collisions): dicts of name (the element path), "
            "shape, file, first_triangle, triangle_count, sphere_set, sphere_index")
        .def_property_readonly(
            "spheres",
            [](const World& w) {
                pyb::list sets;
                for (const auto& s : w.spheres()) {
                    std::vector<double> flat;
                    for (const auto& c : s.centers) flat.insert(flat.end(), {c.x(), c.y(), c.z()});
                    pyb::dict d;
                    d["centers"] = to_numpy(flat.data(), {static_cast<pyb::ssize_t>(s.centers.size()), 3});
                    d["radius"] = s.radius;
                    sets.append(d);
                }
                return sets;
            },
            "Sets of spheres of one radius each: dicts of centers (N, 3) and radius")
        .def_property_readonly(
            "left_out", [](const World& w) { return w.description().left_out; },
            "Models the world file includes that were not found and left out (missing_models='skip'): 'NAME at PATH'")
        .def_property_readonly(
            "floor_z", [](const World& w) { return w.description().floor_z; },
            "How far a building was moved down so that its floor is at z = 0 (its file's z = world z + floor_z)")
        .def_property_readonly(
            "drop_edges",
            [](const World& w) {
                const auto& e = w.description().drop_edges;
                std::vector<double> flat;
                for (const auto& s : e) flat.insert(flat.end(), {s[0].x(), s[0].y(), s[1].x(), s[1].y()});
                return to_numpy(flat.data(), {static_cast<pyb::ssize_t>(e.size()), 2, 2});
            },
            "(E, 2, 2) segments where the floor ends: the ground robot's body may not cross them");

    m.def(
        "lidar_models",
        [] {
            pyb::list out;
            for (const auto& model : lidar_models()) {
                const LidarSpec s = lidar_model_spec(model);
                std::vector<double> deg;
                for (double e : s.elevations) deg.push_back(rad_to_deg(e));
                pyb::dict d;
                d["name"] = model.name;
                d["description"] = model.description;
                d["elevations_deg"] = to_numpy(deg.data(), {static_cast<pyb::ssize_t>(deg.size())});
                d["columns"] = model.columns;
                d["min_range"] = model.min_range;
                d["max_range"] = model.max_range;
                d["range_noise_sd"] = model.range_noise_sd;
                d["height"] = s.height;
                out.append(d);
            }
            return out;
        },
        "The real LiDAR models (sensor names for Sensor.from_yaml, World.scan, models): their beam tables as dicts");

    m.def(
        "route",
        [](const World& w, const pyb::object& waypoints, const pyb::kwargs& kwargs) {
            RouteParams route;
            apply_kwargs(route, RouteParams::table(), kwargs);
            const auto points = points_of(waypoints, "waypoints");
            const RobotParams robot;
            const auto steps = interruptible([&](const std::atomic<bool>&) {
                const BodyCollider body(w.description(), robot.radius, robot.height);
                return route_through(points, body, route);
            });
            return steps_dict(steps);
        },
        pyb::arg("world"), pyb::arg("waypoints"),
        ("A smooth drive through (N, 2) waypoints (docs/buildings.md#routes): dict of arrays t, x, y, z, heading,\n"
         "one entry per model step. Keywords and their defaults:\n" +
         describe(RouteParams::table(), RouteParams{}))
            .c_str());
    m.def(
        "tour",
        [](const World& w, const pyb::object& start, const pyb::kwargs& kwargs) {
            RouteParams route;
            TourParams tour;
            apply_split(route, tour, kwargs);
            std::optional<Vec2> from;
            if (!start.is_none()) from = points_of(pyb::list(pyb::make_tuple(start)), "start").front();
            const RobotParams robot;
            const Tour t = interruptible([&](const std::atomic<bool>&) {
                return make_tour(w.description(), robot.radius, robot.height, from, tour, route);
            });
            pyb::dict d = steps_dict(t.steps);
            std::vector<double> flat;
            for (const auto& p : t.waypoints) flat.insert(flat.end(), {p.x(), p.y()});
            d["waypoints"] = to_numpy(flat.data(), {static_cast<pyb::ssize_t>(t.waypoints.size()), 2});
            d["stats"] = stats_dict(t.stats);
            return d;
        },
        pyb::arg("world"), pyb::arg("start") = pyb::none(),
        ("A closed tour of the world's floor (docs/buildings.md#tours): dict of arrays t, x, y, z, heading, the\n"
         "waypoints (K, 2) and stats (length, coverage, walkable_area, reverse_length, same_length, closing_gap).\n"
         "start: (x, y) or None. Keywords and their defaults:\n" +
         describe(RouteParams::table(), RouteParams{}) + describe(TourParams::table(), TourParams{}))
            .c_str());
    m.def(
        "write_trajectory",
        [](const std::filesystem::path& path, const pyb::dict& d) {
            const auto col = [&](const char* key, bool required) {
                if (!d.contains(key)) {
                    if (required) throw InputError(std::string("trajectory: the dict lacks '") + key + "'");
                    return std::vector<double>{};
                }
                const auto a = real_array(d[key], std::string("trajectory['") + key + "']");
                return std::vector<double>(a.data(), a.data() + a.size());
            };
            write_trajectory_file(path, trajectory_steps(col("t", true), col("x", true), col("y", true),
                                                         col("z", false), col("heading", true), "trajectory arrays"));
        },
        pyb::arg("path"), pyb::arg("trajectory"),
        "Writes a dict of arrays t, x, y, [z], heading as a trajectory file (read_trajectory reads it back exactly)");
}

}  // namespace bvc3d::py

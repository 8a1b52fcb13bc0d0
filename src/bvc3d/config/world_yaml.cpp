#include "bvc3d/config/world_yaml.hpp"

#include <cmath>
#include <filesystem>

#include "bvc3d/config/building.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/recording/scan_file.hpp"
#include "bvc3d/sensor/lidar_models.hpp"
#include "bvc3d/world/mesh_import.hpp"

namespace bvc3d::config {

namespace {

// Numbers that are coordinates or sizes in meters: within ±max_coordinate.
std::vector<double> meters(const YamlView& v, std::size_t n) {
    const auto d = v.as_doubles(n);
    for (double x : d)
        if (std::abs(x) > max_coordinate)
            v.fail("holds " + format_number(x) + ": coordinates and sizes must lie within ±" +
                   format_number(max_coordinate) + " m");
    return d;
}

Vec3 vec3(const YamlView& v) {
    const auto d = meters(v, 3);
    return Vec3(d[0], d[1], d[2]);
}

Vec2 vec2(const YamlView& v) {
    const auto d = meters(v, 2);
    return Vec2(d[0], d[1]);
}

// Whether two segments ab and cd cross or touch (shared endpoints of neighbors excluded by the caller).
bool segments_meet(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
    const auto orient = [](const Vec2& p, const Vec2& q, const Vec2& r) {
        const double v = (q - p).x() * (r - p).y() - (q - p).y() * (r - p).x();
        return (v > 0) - (v < 0);
    };
    const auto on = [](const Vec2& p, const Vec2& q, const Vec2& r) {  // r on segment pq, given collinear
        return std::min(p.x(), q.x()) <= r.x() && r.x() <= std::max(p.x(), q.x()) && std::min(p.y(), q.y()) <= r.y() &&
               r.y() <= std::max(p.y(), q.y());
    };
    const int o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a), o4 = orient(c, d, b);
    if (o1 != o2 && o3 != o4) return true;
    return (o1 == 0 && on(a, b, c)) || (o2 == 0 && on(a, b, d)) || (o3 == 0 && on(c, d, a)) || (o4 == 0 && on(c, d, b));
}

// A simple polygon: no edge crosses another (a figure eight has no inside the robot can use).
void check_simple(const YamlView& v, const Polygon2& poly) {
    const auto& p = poly.points;
    const std::size_t n = p.size();
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j) {
            if (j == i + 1 || (i == 0 && j == n - 1)) continue;  // neighbors share a corner
            if (segments_meet(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n]))
                v.fail("edges " + std::to_string(i) + " and " + std::to_string(j) +
                       " cross: the polygon must not intersect itself");
        }
}

// rect: [xmin, ymin, xmax, ymax] or polygon: [[x, y], ...]
Polygon2 region_from_yaml(const YamlView& v, std::initializer_list<const char*> other_keys = {}) {
    std::vector<std::string> keys{"rect", "polygon"};
    keys.insert(keys.end(), other_keys.begin(), other_keys.end());
    v.expect_map(keys);
    if (v.has("rect") == v.has("polygon")) v.fail("give exactly one of 'rect' or 'polygon'");
    if (v.has("rect")) {
        const auto r = meters(v["rect"], 4);
        if (!(r[2] > r[0] && r[3] > r[1])) v["rect"].fail("needs xmin < xmax and ymin < ymax");
        return Polygon2::rectangle(r[0], r[1], r[2], r[3]);
    }
    const auto pv = v["polygon"];
    if (pv.size() > 10000) pv.fail("has " + std::to_string(pv.size()) + " points; the limit is 10000");
    Polygon2 poly;
    for (std::size_t i = 0; i < pv.size(); ++i) poly.points.push_back(vec2(pv.at(i)));
    if (poly.points.size() < 3 || poly.area() <= 0) pv.fail("needs at least 3 points enclosing a positive area");
    check_simple(pv, poly);
    return poly;
}

Eigen::Isometry3d pose_from_yaml(const YamlView& v, const std::string& position_key) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    if (v.has(position_key)) pose.translation() = vec3(v[position_key]);
    if (v.has("rotation_deg")) {  // roll, pitch, yaw about x, y, z (applied in that order)
        const auto r = v["rotation_deg"].as_doubles(3);
        pose.linear() =
            (Eigen::AngleAxisd(deg_to_rad(r[2]), Vec3::UnitZ()) * Eigen::AngleAxisd(deg_to_rad(r[1]), Vec3::UnitY()) *
             Eigen::AngleAxisd(deg_to_rad(r[0]), Vec3::UnitX()))
                .toRotationMatrix();
    } else if (v.has("yaw_deg")) {
        pose.linear() = Eigen::AngleAxisd(deg_to_rad(v["yaw_deg"].as_double()), Vec3::UnitZ()).toRotationMatrix();
    }
    if (v.has("rotation_deg") && v.has("yaw_deg")) v.fail("give 'yaw_deg' or 'rotation_deg', not both");
    return pose;
}

CrossArenaParams cross_from_yaml(const YamlView& v) {
    CrossArenaParams p;
    read_fields(v, {{"tilt_deg", &p.tilt_deg},
                    {"lean", &p.lean},
                    {"half_width", &p.half_width},
                    {"height", &p.height},
                    {"wall_length", &p.wall_length},
                    {"wall_thickness", &p.wall_thickness},
                    {"start_offset", &p.start_offset},
                    {"flight_clearance", &p.flight_clearance}});
    return p;
}

// The file a `mesh:` or `point_cloud:` object loads: its `file`, relative to the YAML file unless absolute.
std::string mesh_path(const YamlView& mesh) {
    const std::filesystem::path rel = mesh["file"].as_string();
    return rel.is_absolute() ? rel.string() : (std::filesystem::path(mesh.directory()) / rel).string();
}

// Every vertex within ±max_coordinate (after scaling and placing).
void check_coordinates(const YamlView& v, const TriangleMesh& m) {
    for (const auto& p : m.vertices)
        if (!p.allFinite() || p.cwiseAbs().maxCoeff() > max_coordinate)
            v.fail("reaches (" + format_number(p.x()) + ", " + format_number(p.y()) + ", " + format_number(p.z()) +
                   "): coordinates must lie within ±" + format_number(max_coordinate) + " m");
}

void check_mesh(const YamlView& v, const TriangleMesh& m) {
    if (m.empty()) v.fail("produces no triangles");
    check_coordinates(v, m);
    for (std::size_t t = 0; t < m.size(); ++t) {
        const auto c = m.corners(t);
        if (triangle_double_area(c[0], c[1], c[2]) <= 1e-12) v.fail("is degenerate (zero area)");
    }
}

// A `point_cloud:` object: the points of a PCD, PLY or KITTI file drawn as spheres, placed like a
// mesh, optionally cropped in z (after placing).
SphereSet point_cloud_from_yaml(const YamlView& v) {
    v.expect_map({"file", "radius", "position", "yaw_deg", "rotation_deg", "scale", "crop_z"});
    recording::PointCloud cloud;
    try {
        cloud = recording::read_scan(mesh_path(v));
    } catch (const InputError& e) {
        v["file"].fail(e.what());
    }
    SphereSet set;
    set.radius = v.get("radius", set.radius);
    require_positive(v, "radius", set.radius);
    if (set.radius > max_coordinate)  // a size in meters, as a box's: held to the limit meshes are
        v["radius"].fail("is " + format_number(set.radius) + " m: sizes must lie within " +
                         format_number(max_coordinate) + " m");
    const double scale = v.get("scale", 1.0);
    require_positive(v, "scale", scale);
    double zmin = -INFINITY, zmax = INFINITY;
    if (v.has("crop_z")) {
        const auto z = v["crop_z"].as_doubles(2);
        if (!(z[0] < z[1])) v["crop_z"].fail("needs [zmin, zmax] with zmin < zmax");
        zmin = z[0];
        zmax = z[1];
    }
    const Eigen::Isometry3d pose = pose_from_yaml(v, "position");
    set.centers.reserve(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
        const Vec3 c = pose * (scale * Vec3(cloud.xyz[3 * i], cloud.xyz[3 * i + 1], cloud.xyz[3 * i + 2]));
        if (!c.allFinite() || c.cwiseAbs().maxCoeff() > max_coordinate)  // after scaling and placing, as a mesh's
            v.fail("point " + std::to_string(i) + " reaches (" + format_number(c.x()) + ", " + format_number(c.y()) +
                   ", " + format_number(c.z()) + "): coordinates must lie within ±" + format_number(max_coordinate) +
                   " m");
        if (c.z() >= zmin && c.z() <= zmax) set.centers.push_back(c);
    }
    if (set.centers.empty()) v.fail("keeps no points (all cropped away by crop_z)");
    return set;
}

constexpr const char* kObjectKinds = "cross_arena, box, quad, triangle, tilted_wall, mesh or point_cloud";

// One entry of `objects`: a map with exactly one key naming the primitive.
void add_object(const YamlView& obj, WorldDescription& w, std::optional<WorldDescription>& arena) {
    if (!obj.is_map() || obj.keys().size() != 1)
        obj.fail(std::string("each object is a mapping with one key: ") + kObjectKinds);
    const std::string kind = obj.keys().front();
    const YamlView v = obj[kind];
    TriangleMesh part;
    if (kind == "cross_arena") {
        CrossArenaParams p = cross_from_yaml(v);
        try {
            arena = cross_arena(p);
        } catch (const InputError& e) {
            v.fail(e.what());
        }
        part = arena->mesh;
    } else if (kind == "box") {
        v.expect_map({"center", "size", "yaw_deg", "rotation_deg"});
        const Vec3 size = vec3(v["size"]);
        if (!(size.minCoeff() > 0)) v["size"].fail("all three sizes must be > 0");
        part.append(box_mesh(size), pose_from_yaml(v, "center"));
    } else if (kind == "quad") {
        if (!v.is_sequence() || v.size() != 4) v.fail("a quad is a list of 4 corners [x, y, z], in order around it");
        Vec3 c[4];
        for (int i = 0; i < 4; ++i) c[i] = vec3(v.at(i));
        part.add_quad(c[0], c[1], c[2], c[3]);
    } else if (kind == "triangle") {
        if (!v.is_sequence() || v.size() != 3) v.fail("a triangle is a list of 3 corners [x, y, z]");
        part.add_triangle(vec3(v.at(0)), vec3(v.at(1)), vec3(v.at(2)));
    } else if (kind == "tilted_wall") {
        TiltedWall t;
        double yaw = 0.0, tilt = 0.0;
        read_fields(v,
                    {{"length", &t.length},
                     {"thickness", &t.thickness},
                     {"height", &t.height},
                     {"yaw_deg", &yaw},
                     {"tilt_deg", &tilt}},
                    {"center"});
        t.center = vec2(v["center"]);
        t.yaw = deg_to_rad(yaw);
        require_positive(v, "length", t.length);
        require_positive(v, "thickness", t.thickness);
        require_positive(v, "height", t.height);
        require_range(v, "tilt_deg", tilt, -89.0, 89.0);
        t.tilt = deg_to_rad(tilt);
        part = tilted_wall_mesh(t);
    } else if (kind == "mesh") {
        v.expect_map({"file", "position", "yaw_deg", "rotation_deg", "scale"});
        TriangleMesh loaded;
        try {
            loaded = load_mesh_file(mesh_path(v));
        } catch (const InputError& e) {
            v["file"].fail(e.what());
        }
        const double scale = v.get("scale", 1.0);
        require_positive(v, "scale", scale);
        for (auto& p : loaded.vertices) p *= scale;
        part.append(loaded, pose_from_yaml(v, "position"));
        if (part.empty()) v.fail("mesh has no triangles");
        check_coordinates(v, part);
        w.mesh.append(part);
        return;  // assimp already dropped degenerate triangles
    } else if (kind == "point_cloud") {
        w.spheres.push_back(point_cloud_from_yaml(v));
        return;
    } else {
        obj.fail("unknown object kind '" + kind + "' (expected " + kObjectKinds + ")");
    }
    check_mesh(v, part);
    w.mesh.append(part);
}

}  // namespace

namespace {

// flight_volume: {rect: [...] or polygon: [...] (default: the walkable region), z_min: Z, z_max: Z}.
// The volume must lie within the geometry's bounds: a flying body outside every wall is a mistake.
FlightVolume flight_from_yaml(const YamlView& v, const WorldDescription& w) {
    if (!v.is_map()) v.fail("must be a mapping: {rect: [xmin, ymin, xmax, ymax], z_min: Z, z_max: Z}");
    FlightVolume f;
    if (v.has("rect") || v.has("polygon")) {
        f.region = region_from_yaml(v, {"z_min", "z_max"});
    } else {
        v.expect_map({"rect", "polygon", "z_min", "z_max"});
        if (w.walkable.points.size() < 3)
            v.fail("needs a 'rect' or 'polygon' (the world has no walkable region to default to)");
        f.region = w.walkable;
    }
    if (!v.has("z_min")) v.fail_key("z_min", "is required (m, the volume's floor)");
    if (!v.has("z_max")) v.fail_key("z_max", "is required (m, the volume's ceiling)");
    f.z_min = v["z_min"].as_double();
    f.z_max = v["z_max"].as_double();
    if (!std::isfinite(f.z_min) || !std::isfinite(f.z_max)) v.fail("z_min and z_max must be finite");
    if (!(f.z_max > f.z_min))
        v.fail("is empty: z_max (" + format_number(f.z_max) + ") must be above z_min (" + format_number(f.z_min) + ")");
    Eigen::AlignedBox3d world_box;
    for (const auto& p : w.mesh.vertices) world_box.extend(p);
    const auto box = f.bounds();
    const double slack = 1e-9 * std::max(1.0, world_box.sizes().maxCoeff());
    if (!(box.min().array() >= world_box.min().array() - slack).all() ||
        !(box.max().array() <= world_box.max().array() + slack).all())
        v.fail("reaches outside the world's geometry (x " + format_number(world_box.min().x()) + " to " +
               format_number(world_box.max().x()) + ", y " + format_number(world_box.min().y()) + " to " +
               format_number(world_box.max().y()) + ", z " + format_number(world_box.min().z()) + " to " +
               format_number(world_box.max().z()) + " m)");
    return f;
}

// The one list of world presets: cross arenas, some with their tilt fixed by the name, and the
// flying agents' worlds (no tilt).
struct WorldPreset {
    std::string name;
    std::optional<double> fixed_tilt;                       // none: the preset takes a tilt (default 0)
    CrossArenaParams (*params)(double tilt_deg) = nullptr;  // a cross arena ...
    WorldDescription (*fixed_world)() = nullptr;            // ... or a world of its own
};

CrossArenaParams paper_cross(double tilt_deg) { return CrossArenaParams{.tilt_deg = tilt_deg}; }

const std::vector<WorldPreset>& world_presets() {
    static const std::vector<WorldPreset> presets{
        {"cross", std::nullopt, paper_cross},
        {"cross-0", 0.0, paper_cross},
        {"cross-30", 30.0, paper_cross},
        {"cross-45", 45.0, paper_cross},
        {"cross-60", 60.0, paper_cross},
        {"cross-webots", std::nullopt, CrossArenaParams::webots},
        {"flight-room", std::nullopt, nullptr, flight_room},
        {"atrium", std::nullopt, nullptr, atrium},
    };
    return presets;
}

const WorldPreset* find_world_preset(const std::string& name) {
    for (const auto& p : world_presets())
        if (p.name == name) return &p;
    return nullptr;
}

}  // namespace

std::vector<std::string> world_preset_names() {
    std::vector<std::string> names;
    for (const auto& p : world_presets()) names.push_back(p.name);
    return names;
}

bool world_preset_takes_tilt(const std::string& name) {
    const WorldPreset* p = find_world_preset(name);
    return p && p->params && !p->fixed_tilt;
}

WorldDescription world_from_yaml(const YamlView& v) {
    const bool sdf = v.has("sdf");  // a Gazebo building (config/building.hpp)
    if (sdf)
        v.expect_map({"name", "sdf", "model_path", "resource_path", "geometry", "missing_models", "collada_up_axis",
                      "floor_z", "step_height", "walkable", "start", "flight_volume"});
    else v.expect_map({"name", "objects", "walkable", "start", "flight_volume"});
    WorldDescription w;
    std::optional<WorldDescription> arena;
    const YamlView objects = sdf ? v["sdf"] : v["objects"];
    if (sdf) {
        w = building_from_yaml(v);
    } else {
        w.name = v.get("name", std::filesystem::path(v.file()).stem().string());
        w.file = v.file();
        if (objects.size() == 0) objects.fail("lists no objects: a world needs geometry");
        for (std::size_t i = 0; i < objects.size(); ++i) add_object(objects.at(i), w, arena);
    }

    if (arena) w.tilt_deg = arena->tilt_deg;
    if (static_cast<double>(w.mesh.size()) > max_mesh_triangles)
        objects.fail("hold " + std::to_string(w.mesh.size()) + " triangles; the limit is " +
                     format_number(max_mesh_triangles));
    if (v.has("walkable")) {
        w.walkable = region_from_yaml(v["walkable"]);
    } else if (arena) {
        w.walkable = arena->walkable;
    } else if (!sdf && !v.has("flight_volume")) {  // a building's is its floor's extent
        v.fail_key("walkable",
                   "is required (the floor region the robot may use) unless the world has a cross_arena "
                   "or a flight_volume");
    }
    if (v.has("flight_volume") && !(sdf && v["flight_volume"].is_scalar())) {  // sdf: `storey` is the building's
        w.flight = flight_from_yaml(v["flight_volume"], w);
    } else if (arena && !v.has("walkable")) {
        w.flight = arena->flight;
    }
    if (w.walkable.points.empty()) {  // a flight-only world: no ground robot, no start region
        if (v.has("start"))
            v.fail_key("start", "needs a walkable region (flying agents start anywhere in the flight volume)");
        return w;
    }
    // A floor with no geometry over it is a world the sensors cannot see.
    Eigen::AlignedBox2d geometry;
    for (const auto& p : w.mesh.vertices) geometry.extend(Vec2(p.x(), p.y()));
    for (const auto& set : w.spheres)  // point clouds
        for (const auto& c : set.centers) geometry.extend(Vec2(c.x(), c.y()));
    if (!geometry.intersects(w.walkable.bounds()))
        (v.has("walkable") ? v["walkable"] : objects)
            .fail("the walkable region lies entirely outside the world's geometry");
    if (v.has("start")) {
        const YamlView s = v["start"];
        if (s.has("points")) {
            s.expect_map({"points"});
            for (std::size_t i = 0; i < s["points"].size(); ++i) w.start.points.push_back(vec2(s["points"].at(i)));
            if (w.start.points.empty()) s["points"].fail("must list at least one [x, y] point");
            for (std::size_t i = 0; i < w.start.points.size(); ++i)
                if (!w.walkable.contains(w.start.points[i]))
                    s["points"].at(i).fail("start point lies outside the walkable region");
        } else {
            w.start.region = region_from_yaml(s);
        }
    } else if (arena && !v.has("walkable")) {
        w.start = arena->start;
    } else {
        w.start.region = w.walkable;
    }
    return w;
}

WorldDescription load_world_file(const std::string& path) { return world_from_yaml(YamlView::load_file(path)); }

std::vector<std::string> world_file_meshes(const std::string& path) {
    std::vector<std::string> files;
    if (is_gazebo_file(path)) {  // the file itself is hashed by the caller
        files = gazebo_world_files(path);
        files.erase(std::remove(files.begin(), files.end(), path), files.end());
        return files;
    }
    const YamlView v = YamlView::load_file(path);
    if (v.has("sdf")) return building_yaml_files(v);
    if (!v.has("objects") || !v["objects"].is_sequence()) return files;
    const YamlView objects = v["objects"];
    for (std::size_t i = 0; i < objects.size(); ++i) {
        const YamlView o = objects.at(i);
        for (const char* kind : {"mesh", "point_cloud"})
            if (o.has(kind) && o[kind].has("file")) files.push_back(mesh_path(o[kind]));
    }
    return files;
}

WorldDescription resolve_world(const std::string& name, std::optional<double> tilt_deg, const std::string& lean,
                               MissingModels missing) {
    if (missing == MissingModels::skip && !is_gazebo_file(name))
        throw InputError("missing models: 'skip' applies to Gazebo world files (.world, .sdf), not to '" + name +
                         "' (a world YAML with `sdf:` says it with its key missing_models: skip)");
    if (const WorldPreset* preset = find_world_preset(name)) {
        if (preset->fixed_world) {
            if (tilt_deg)
                throw InputError("a tilt only applies to the cross and cross-webots worlds, not to '" + name + "'");
            return preset->fixed_world();
        }
        if (preset->fixed_tilt && tilt_deg)
            throw InputError("a tilt only applies to the cross and cross-webots worlds; '" + name + "' fixes its own");
        CrossArenaParams p = preset->params(preset->fixed_tilt ? *preset->fixed_tilt : tilt_deg.value_or(0.0));
        p.lean = lean;
        WorldDescription w = cross_arena(p);
        if (!preset->fixed_tilt && name != "cross") w.name = name + "-" + format_number(p.tilt_deg);
        return w;
    }
    const auto presets = world_preset_names();
    if (tilt_deg) throw InputError("a tilt only applies to the cross and cross-webots worlds, not to '" + name + "'");
    std::error_code ec;
    if (!std::filesystem::exists(name, ec)) {
        std::string list;
        for (const auto& p : presets) list += (list.empty() ? "" : ", ") + p;
        throw InputError("world '" + name + "' is neither a preset (" + list +
                         ") nor an existing YAML or Gazebo world (.world, .sdf) file");
    }
    if (is_gazebo_file(name)) {
        BuildingSpec spec;
        spec.file = name;
        spec.gazebo.skip_missing_models = missing == MissingModels::skip;
        return building_world(spec);
    }
    return load_world_file(name);
}

namespace {

// The built-in sensors, by name: the paper's scanners, then the real LiDAR models (sensor/lidar_models.hpp).
const std::vector<std::pair<std::string, LidarSpec>>& builtin_sensors() {
    static const std::vector<std::pair<std::string, LidarSpec>> sensors = [] {
        std::vector<std::pair<std::string, LidarSpec>> list{
            {"horizontal", LidarSpec::horizontal()},
            {"spherical", LidarSpec::spherical()},
            {"spherical-full", LidarSpec::spherical_full()},
            {"spherical-authors", LidarSpec::spherical_as_authors()},
        };
        for (const auto& m : lidar_models()) list.emplace_back(m.name, lidar_model_spec(m));
        return list;
    }();
    return sensors;
}

const LidarSpec* find_builtin_sensor(const std::string& name) {
    for (const auto& [n, spec] : builtin_sensors())
        if (n == name) return &spec;
    return nullptr;
}

// "vlp16, hdl32, ..." (quoted: "'vlp16', 'hdl32', ...").
std::string lidar_model_list(bool quoted = false) {
    std::string list;
    for (const auto& m : lidar_models()) list += (list.empty() ? "" : ", ") + (quoted ? "'" + m.name + "'" : m.name);
    return list;
}

// The paper's scanners: "horizontal, spherical, ..." (quoted: "'horizontal', 'spherical', ...").
std::string scanner_list(bool quoted = false) {
    std::string list;
    for (const auto& [name, spec] : builtin_sensors())
        if (!find_lidar_model(name)) list += (list.empty() ? "" : ", ") + (quoted ? "'" + name + "'" : name);
    return list;
}

// The rows an upper-half model keeps of a beam table: elevations >= 0 (as `keep_rows: upper` of the
// spherical scanner).
LidarSpec upper_rows(LidarSpec s) {
    std::erase_if(s.elevations, [](double e) { return e < 0; });
    return s;
}

}  // namespace

std::vector<std::string> sensor_preset_names() {
    std::vector<std::string> names;
    for (const auto& [name, spec] : builtin_sensors()) names.push_back(name);
    return names;
}

LidarSpec sensor_from_yaml(const YamlView& v) {
    if (v.is_scalar()) {
        const std::string name = v.as_string();
        if (const LidarSpec* s = find_builtin_sensor(name)) return *s;
        v.fail("expected " + scanner_list() + ", a LiDAR model (" + lidar_model_list() + "), or a sensor mapping");
    }
    if (!v.is_map()) v.fail("expected horizontal, spherical, or a sensor mapping (or a LiDAR model's name)");
    const std::string preset = v.get("preset", "");
    const bool own_rows = v.has("elevations") || v.has("elevations_deg");
    LidarSpec s;
    if (preset == "horizontal") {
        s = LidarSpec::horizontal();
        if (v.has("keep_rows")) v.fail_key("keep_rows", "only applies to the spherical preset and the LiDAR models");
    } else if (preset == "spherical") {
        const std::string rows = v.get("keep_rows", "upper");
        if (rows != "upper" && rows != "all") v["keep_rows"].fail("must be 'upper' or 'all'");
        if (own_rows && v.has("keep_rows")) v.fail_key("keep_rows", "cannot be combined with elevations");
        s = LidarSpec::spherical(rows == "upper");
    } else if (const LidarModel* model = find_lidar_model(preset)) {
        const std::string rows = v.get("keep_rows", "all");  // a real scanner's beams, all of them
        if (rows != "upper" && rows != "all") v["keep_rows"].fail("must be 'upper' or 'all'");
        if (own_rows && v.has("keep_rows")) v.fail_key("keep_rows", "cannot be combined with elevations");
        s = rows == "upper" ? upper_rows(lidar_model_spec(*model)) : lidar_model_spec(*model);
    } else if (!preset.empty()) {
        v["preset"].fail("unknown sensor preset '" + preset +
                         "' (expected horizontal, spherical or a LiDAR model: " + lidar_model_list() + ")");
    } else if (!own_rows) {
        v.fail("a custom sensor needs 'elevations_deg' (or a 'preset')");
    } else {
        s.name = "custom";
    }
    read_table(v, s, LidarSpec::table(), {"preset", "keep_rows"});
    return s;
}

std::string builtin_sensor_name(const LidarSpec& s) {
    const auto& table = LidarSpec::table();
    const std::string text = params::yaml_lines(table, s, "");
    for (const auto& [name, spec] : builtin_sensors())
        if (text == params::yaml_lines(table, spec, "")) return name;
    return "";
}

void write_sensor(params::CommentedYaml& out, const LidarSpec& s, const std::string& indent) {
    out.fields(LidarSpec::table(), s, indent);
}

std::string sensor_to_commented_yaml(const LidarSpec& s) {
    params::CommentedYaml out;
    out.comment("",
                "A sensor (docs/worlds.md#sensors): every key. Read by --sensor FILE, or as a model's sensor mapping.");
    write_sensor(out, s, "");
    return out.str();
}

LidarSpec resolve_sensor(const std::string& name) {
    if (const LidarSpec* s = find_builtin_sensor(name)) return *s;
    std::error_code ec;
    if (!std::filesystem::exists(name, ec))
        throw InputError("sensor '" + name + "' is neither " + scanner_list(true) + ", a LiDAR model (" +
                         lidar_model_list(true) + ") nor an existing YAML file");
    const YamlView v = YamlView::load_file(name);
    return sensor_from_yaml(v.has("sensor") ? v["sensor"] : v);
}

}  // namespace bvc3d::config

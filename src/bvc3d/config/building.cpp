#include "bvc3d/config/building.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/world/ray_caster.hpp"

namespace bvc3d::config {

namespace {

namespace fs = std::filesystem;

std::string levels_text(const std::vector<FloorLevel>& levels) {
    std::string s;
    for (const auto& l : levels) s += (s.empty() ? "" : ", ") + format_number(std::round(l.z * 1000) / 1000) + " m";
    return s;
}

// The median height of the first geometry above the floor's held cells (at most ~4000 of them,
// evenly spread): the storey's ceiling (infinity when most of the floor is under the open sky).
double storey_ceiling(const WorldDescription& w, const FloorMap& map) {
    const RayCaster caster(w.mesh, w.spheres);
    const std::size_t held = static_cast<std::size_t>(std::count(map.held.begin(), map.held.end(), 1));
    const std::size_t stride = std::max<std::size_t>(1, held / 4000);
    std::vector<double> heights;
    std::size_t k = 0;
    for (int y = 0; y < map.ny; ++y)
        for (int x = 0; x < map.nx; ++x) {
            if (!map.held[static_cast<std::size_t>(y) * map.nx + x] || k++ % stride) continue;
            const Vec3 from(map.box.min().x() + (x + 0.5) * map.cell, map.box.min().y() + (y + 0.5) * map.cell, 1e-3);
            const double up = caster.cast(from, Vec3::UnitZ(), 1e3);
            heights.push_back(up == RayCaster::no_hit ? up : from.z() + up);  // open sky: infinity
        }
    if (heights.empty()) return RayCaster::no_hit;
    std::nth_element(heights.begin(), heights.begin() + static_cast<std::ptrdiff_t>(heights.size() / 2), heights.end());
    return heights[heights.size() / 2];
}

}  // namespace

std::vector<FloorLevel> building_floors(const GazeboScene& scene) {
    // Horizontal triangles with no headroom (the underside of a slab, a shelf under another) are
    // not floors: each is tried at 7 points, and left out unless most have room above them.
    constexpr double headroom = 0.5;  // m
    const FloorOptions options;
    const RayCaster caster(scene.mesh, scene.spheres);
    std::vector<char> skip(scene.mesh.size(), 0);
    for (std::size_t t = 0; t < scene.mesh.size(); ++t) {
        const auto c = scene.mesh.corners(t);
        const Vec3 n = (c[1] - c[0]).cross(c[2] - c[0]);
        if (!(std::abs(n.z()) >= std::cos(deg_to_rad(options.max_tilt_deg)) * n.norm())) continue;
        int room = 0;
        for (const auto& [a, b] : {std::pair{1.0 / 3, 1.0 / 3},
                                   {0.8, 0.1},
                                   {0.1, 0.8},
                                   {0.1, 0.1},
                                   {0.45, 0.45},
                                   {0.45, 0.1},
                                   {0.1, 0.45}}) {
            const Vec3 p = c[0] + a * (c[1] - c[0]) + b * (c[2] - c[0]) + Vec3(0, 0, 1e-3);
            room += caster.cast(p, Vec3::UnitZ(), headroom) == RayCaster::no_hit;
        }
        skip[t] = room < 4;
    }
    std::vector<char> ground = skip;
    for (const auto& p : scene.parts)
        if (p.ground_plane)
            std::fill(ground.begin() + static_cast<std::ptrdiff_t>(p.first_triangle),
                      ground.begin() + static_cast<std::ptrdiff_t>(p.first_triangle + p.triangle_count), 1);
    auto levels = floor_levels(scene.mesh, ground, options);
    return levels.empty() ? floor_levels(scene.mesh, skip, options) : levels;
}

const std::vector<std::string>& missing_models_names() {
    static const std::vector<std::string> names{"error", "skip"};
    return names;
}

MissingModels parse_missing_models(const std::string& text) {
    const auto& names = missing_models_names();
    for (std::size_t i = 0; i < names.size(); ++i)
        if (text == names[i]) return static_cast<MissingModels>(i);
    throw InputError("must be '" + names[0] + "' or '" + names[1] + "', got '" + text + "'");
}

WorldDescription building_world(const BuildingSpec& spec) {
    GazeboScene scene = load_gazebo_world(spec.file, spec.gazebo);
    const std::string where = "Gazebo world '" + spec.file + "'";
    const auto levels = building_floors(scene);
    if (levels.empty())
        throw InputError(where + ": has no floor (no horizontal geometry of at least " +
                         format_number(FloorOptions{}.min_area) + " m² for a ground agent to stand on)");
    // The default: the lowest level with at least a quarter of the largest one's area (a pit, a
    // platform or a step is not the building's floor).
    double largest = 0;
    for (const auto& l : levels) largest = std::max(largest, l.area);
    FloorLevel floor =
        *std::find_if(levels.begin(), levels.end(), [&](const FloorLevel& l) { return l.area >= 0.25 * largest; });
    if (spec.floor_z) {
        if (!std::isfinite(*spec.floor_z)) throw InputError(where + ": floor_z must be a finite height");
        floor = *std::min_element(levels.begin(), levels.end(), [&](const FloorLevel& a, const FloorLevel& b) {
            return std::abs(a.z - *spec.floor_z) < std::abs(b.z - *spec.floor_z);
        });
        constexpr double max_miss = 0.5;  // m
        if (std::abs(floor.z - *spec.floor_z) > max_miss)
            throw InputError(where + ": has no floor at floor_z " + format_number(*spec.floor_z) + " m (within " +
                             format_number(max_miss) + " m); its floors are at " + levels_text(levels));
    }

    WorldDescription w;
    w.name = spec.name.empty() ? fs::path(spec.file).stem().string() : spec.name;
    w.floor_z = floor.z;
    if (!(spec.step_height >= 0 && spec.step_height < 1))
        throw InputError(where + ": step_height must be at least 0 and below 1 m, got " +
                         format_number(spec.step_height));
    w.step_height = spec.step_height;
    w.mesh = std::move(scene.mesh);
    for (auto& v : w.mesh.vertices) v.z() -= floor.z;
    w.spheres = std::move(scene.spheres);
    for (auto& set : w.spheres)
        for (auto& c : set.centers) c.z() -= floor.z;
    w.left_out = scene.missing_models;
    for (const auto& p : scene.parts)
        w.parts.push_back(
            WorldPart{p.path, p.shape, p.file, p.first_triangle, p.triangle_count, p.sphere_set, p.sphere_index});

    const FloorMap map = floor_map(w.mesh);
    if (map.held_area() <= 0)
        throw InputError(where + ": the floor at " + format_number(floor.z) + " m has no geometry to stand on");
    w.drop_edges = map.edges;
    const auto box = map.held_bounds();
    w.walkable = Polygon2::rectangle(box.min().x(), box.min().y(), box.max().x(), box.max().y());
    w.start.region = w.walkable;
    if (spec.flight) {
        const double ceiling = storey_ceiling(w, map);
        const double clearance = spec.flight->clearance;
        if (ceiling == RayCaster::no_hit)
            throw InputError(where + ": the floor at " + format_number(floor.z) +
                             " m is under the open sky: a storey flight volume needs a ceiling");
        if (!(ceiling - clearance > clearance))
            throw InputError(where + ": the storey at " + format_number(floor.z) + " m is " + format_number(ceiling) +
                             " m high: no room for a flight volume " + format_number(clearance) +
                             " m clear of floor and ceiling");
        w.flight = FlightVolume{w.walkable, clearance, ceiling - clearance};
    }
    return w;
}

namespace {

GazeboOptions gazebo_options_from_yaml(const YamlView& v, BuildingSpec& spec) {
    GazeboOptions o;
    const auto in_yaml_dir = [&](const std::string& p) {
        const fs::path rel(p);
        return rel.is_absolute() ? p : (fs::path(v.directory()) / rel).string();
    };
    spec.file = in_yaml_dir(v["sdf"].as_string());
    if (!is_gazebo_file(spec.file)) v["sdf"].fail("must name a Gazebo world file (.world or .sdf)");
    // Lists of folders, relative to the YAML, that must exist.
    const auto folders = [&](const char* key, std::vector<std::string>& out) {
        if (!v.has(key)) return;
        const YamlView list = v[key];
        if (!list.is_sequence()) list.fail("must be a list of folders");
        for (std::size_t i = 0; i < list.size(); ++i) {
            const std::string dir = in_yaml_dir(list.at(i).as_string());
            std::error_code ec;
            if (!fs::is_directory(dir, ec)) list.at(i).fail("folder '" + dir + "' does not exist");
            out.push_back(dir);
        }
    };
    folders("model_path", o.model_path);
    folders("resource_path", o.resource_path);
    const std::string geometry = v.get("geometry", "visual");
    if (geometry != "visual" && geometry != "collision") v["geometry"].fail("must be 'visual' or 'collision'");
    o.geometry = geometry == "visual" ? GazeboOptions::Geometry::visual : GazeboOptions::Geometry::collision;
    if (v.has("missing_models")) try {
            o.skip_missing_models = parse_missing_models(v["missing_models"].as_string()) == MissingModels::skip;
        } catch (const ConfigError&) {
            throw;
        } catch (const InputError& e) {
            v["missing_models"].fail(e.what());
        }
    const std::string up = v.get("collada_up_axis", "ignored");
    if (up != "ignored" && up != "declared") v["collada_up_axis"].fail("must be 'ignored' (as Gazebo) or 'declared'");
    o.collada_up_axis = up == "ignored" ? ColladaUpAxis::ignored : ColladaUpAxis::to_z_up;
    return o;
}

}  // namespace

WorldDescription building_from_yaml(const YamlView& v) {
    BuildingSpec spec;
    spec.gazebo = gazebo_options_from_yaml(v, spec);
    spec.name = v.get("name", std::filesystem::path(v.file()).stem().string());
    if (v.has("floor_z")) spec.floor_z = v["floor_z"].as_double();
    spec.step_height = v.get("step_height", spec.step_height);
    if (!(spec.step_height >= 0 && spec.step_height < 1)) v["step_height"].fail("must be at least 0 and below 1 m");
    if (v.has("flight_volume") && v["flight_volume"].is_scalar()) {
        if (v["flight_volume"].as_string() != "storey")
            v["flight_volume"].fail("must be 'storey' or a mapping {rect or polygon, z_min, z_max}");
        spec.flight = StoreyFlight{};
    }
    try {
        WorldDescription w = building_world(spec);
        w.file = v.file();
        return w;
    } catch (const InputError& e) {
        v["sdf"].fail(e.what());
    }
}

std::vector<std::string> building_yaml_files(const YamlView& v) {
    BuildingSpec spec;
    const GazeboOptions o = gazebo_options_from_yaml(v, spec);
    return gazebo_world_files(spec.file, o);
}

}  // namespace bvc3d::config

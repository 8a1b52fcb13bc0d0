#include "bvc3d/world/world.hpp"

#include <cmath>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/world/ray_caster.hpp"

namespace bvc3d {

namespace {

void require(bool ok, const std::string& what) {
    if (!ok) throw InputError("cross arena: " + what);
}

// Signs of the corner named by `lean`, e.g. "+x-y" -> (+1, -1).
std::pair<double, double> lean_signs(const std::string& lean) {
    if (lean.size() == 4 && (lean[0] == '+' || lean[0] == '-') && lean[1] == 'x' &&
        (lean[2] == '+' || lean[2] == '-') && lean[3] == 'y')
        return {lean[0] == '+' ? 1.0 : -1.0, lean[2] == '+' ? 1.0 : -1.0};
    std::string list;
    for (const auto& l : cross_arena_leans()) list += (list.empty() ? "" : ", ") + l;
    throw InputError("cross arena: lean '" + lean + "' is not one of " + list);
}

}  // namespace

const std::vector<std::string>& cross_arena_leans() {
    static const std::vector<std::string> leans{"+x+y", "+x-y", "-x+y", "-x-y"};
    return leans;
}

CrossArenaParams CrossArenaParams::webots(double tilt_deg) {
    constexpr double outer_wall_center = 5.0, outer_wall_thickness = 0.3;
    constexpr double wall_height = 2.4, ceiling_thickness = 0.3;
    CrossArenaParams p;
    p.tilt_deg = tilt_deg;
    p.half_width = outer_wall_center - outer_wall_thickness / 2;  // 4.85
    p.height = wall_height - ceiling_thickness / 2;               // 2.25: the slab is centered on the walls' tops
    return p;
}

WorldDescription cross_arena(const CrossArenaParams& p) {
    const auto [sx, sy] = lean_signs(p.lean);
    require(std::isfinite(p.tilt_deg) && p.tilt_deg >= 0.0 && p.tilt_deg < 90.0,
            "tilt_deg must be in [0, 90), got " + format_number(p.tilt_deg));
    require(p.half_width > 0 && p.height > 0 && p.wall_thickness > 0 && p.wall_length > 0, "sizes must be positive");
    require(p.half_width <= max_coordinate && p.height <= max_coordinate && p.wall_thickness <= max_coordinate,
            "sizes must be at most " + format_number(max_coordinate) + " m");
    require(p.wall_length < 2.0 * p.half_width, "wall_length must be shorter than the arena");
    const double alpha = deg_to_rad(p.tilt_deg);
    const double reach = p.height * std::tan(alpha) + 0.5 * p.wall_thickness / std::cos(alpha);
    require(reach < p.half_width,
            "tilt_deg " + format_number(p.tilt_deg) + " makes the central walls' tops pass through the outer walls");
    require(std::abs(p.start_offset) < p.half_width, "start_offset must lie inside the arena");
    require(std::isfinite(p.flight_clearance) && p.flight_clearance >= 0 && 2 * p.flight_clearance < p.height,
            "flight_clearance must be >= 0 and leave room between floor and ceiling");

    WorldDescription w;
    w.name = "cross-" + format_number(p.tilt_deg);
    w.tilt_deg = p.tilt_deg;
    const double a = p.half_width, h = p.height;
    auto& m = w.mesh;
    m.add_quad(Vec3(-a, -a, 0), Vec3(a, -a, 0), Vec3(a, a, 0), Vec3(-a, a, 0));    // floor
    m.add_quad(Vec3(-a, -a, h), Vec3(-a, a, h), Vec3(a, a, h), Vec3(a, -a, h));    // ceiling
    m.add_quad(Vec3(-a, -a, 0), Vec3(-a, a, 0), Vec3(-a, a, h), Vec3(-a, -a, h));  // x = -a
    m.add_quad(Vec3(a, -a, 0), Vec3(a, -a, h), Vec3(a, a, h), Vec3(a, a, 0));      // x = +a
    m.add_quad(Vec3(-a, -a, 0), Vec3(-a, -a, h), Vec3(a, -a, h), Vec3(a, -a, 0));  // y = -a
    m.add_quad(Vec3(-a, a, 0), Vec3(a, a, 0), Vec3(a, a, h), Vec3(-a, a, h));      // y = +a

    // Wall A runs along x and leans toward sy·y; wall B runs along y and leans toward sx·x.
    // For yaw = 90° the left normal is -x, hence the sign flip on B's tilt.
    TiltedWall wall{.center = Vec2(0, 0),
                    .length = p.wall_length,
                    .thickness = p.wall_thickness,
                    .height = h,
                    .yaw = 0.0,
                    .tilt = sy * alpha};
    m.append(tilted_wall_mesh(wall));
    wall.yaw = pi / 2;
    wall.tilt = -sx * alpha;
    m.append(tilted_wall_mesh(wall));

    w.walkable = Polygon2::rectangle(-a, -a, a, a);
    const double o = p.start_offset;
    w.start.points = {Vec2(o, o), Vec2(-o, o), Vec2(-o, -o), Vec2(o, -o)};
    w.flight = FlightVolume{w.walkable, p.flight_clearance, p.height - p.flight_clearance};
    return w;
}

Eigen::AlignedBox3d FlightVolume::bounds() const {
    const auto box = region.bounds();
    return Eigen::AlignedBox3d(Vec3(box.min().x(), box.min().y(), z_min), Vec3(box.max().x(), box.max().y(), z_max));
}

namespace {

// A closed room: floor, ceiling and four walls, the same quads (in the same order) as the room's
// YAML file in configs/worlds lists.
void add_room(TriangleMesh& m, double hx, double hy, double h) {
    m.add_quad(Vec3(-hx, -hy, 0), Vec3(hx, -hy, 0), Vec3(hx, hy, 0), Vec3(-hx, hy, 0));    // floor
    m.add_quad(Vec3(-hx, -hy, h), Vec3(-hx, hy, h), Vec3(hx, hy, h), Vec3(hx, -hy, h));    // ceiling
    m.add_quad(Vec3(-hx, -hy, 0), Vec3(-hx, hy, 0), Vec3(-hx, hy, h), Vec3(-hx, -hy, h));  // x = -hx
    m.add_quad(Vec3(hx, -hy, 0), Vec3(hx, -hy, h), Vec3(hx, hy, h), Vec3(hx, hy, 0));      // x = +hx
    m.add_quad(Vec3(-hx, -hy, 0), Vec3(-hx, -hy, h), Vec3(hx, -hy, h), Vec3(hx, -hy, 0));  // y = -hy
    m.add_quad(Vec3(-hx, hy, 0), Vec3(hx, hy, 0), Vec3(hx, hy, h), Vec3(-hx, hy, h));      // y = +hy
}

void add_box(TriangleMesh& m, const Vec3& center, const Vec3& size) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = center;
    m.append(box_mesh(size), pose);
}

constexpr double flight_clearance = 0.2;  // m between the flight volume and floor or ceiling

}  // namespace

WorldDescription flight_room() {
    WorldDescription w;
    w.name = "flight-room";
    const double hx = 2.9, hy = 2.3, h = 2.7;
    add_room(w.mesh, hx, hy, h);
    w.flight = FlightVolume{Polygon2::rectangle(-hx, -hy, hx, hy), flight_clearance, h - flight_clearance};
    return w;
}

WorldDescription atrium() {
    WorldDescription w;
    w.name = "atrium";
    const double a = 5.0, h = 6.0;
    add_room(w.mesh, a, a, h);
    // The mezzanine ring: a 0.2 m slab at 2.8-3.0 m over the 1.5 m band along the walls.
    add_box(w.mesh, Vec3(0, 4.25, 2.9), Vec3(10, 1.5, 0.2));
    add_box(w.mesh, Vec3(0, -4.25, 2.9), Vec3(10, 1.5, 0.2));
    add_box(w.mesh, Vec3(4.25, 0, 2.9), Vec3(1.5, 7, 0.2));
    add_box(w.mesh, Vec3(-4.25, 0, 2.9), Vec3(1.5, 7, 0.2));
    // Two pillars, placed off the diagonals so that no symmetry maps the hall onto itself.
    add_box(w.mesh, Vec3(-1.5, 1.0, 3.0), Vec3(0.6, 0.6, 6.0));
    add_box(w.mesh, Vec3(2.0, -1.5, 3.0), Vec3(0.6, 0.6, 6.0));
    w.flight = FlightVolume{Polygon2::rectangle(-a, -a, a, a), flight_clearance, h - flight_clearance};
    return w;
}

bool WorldDescription::has_geometry() const {
    if (!mesh.empty()) return true;
    for (const auto& set : spheres)
        if (!set.centers.empty()) return true;
    return false;
}

Eigen::AlignedBox3d WorldDescription::bounds() const {
    Eigen::AlignedBox3d box;
    for (std::size_t t = 0; t < mesh.size(); ++t)
        for (const Vec3& c : mesh.corners(t)) box.extend(c);
    for (const auto& set : spheres)
        for (const Vec3& c : set.centers) {
            box.extend(c - Vec3::Constant(set.radius));
            box.extend(c + Vec3::Constant(set.radius));
        }
    return box;
}

World::World(WorldDescription description)
    : desc_(std::move(description)), caster_(std::make_shared<RayCaster>(desc_.mesh, desc_.spheres)) {}

}  // namespace bvc3d

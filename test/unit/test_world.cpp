// Ray distances in the paper's arenas against hand-solved intersections (docs/model-reference.md#the-cross-arena).
//
// The oracle is written independently of the triangle mesh: each central wall is the box
// |u| <= 3.5, |w| <= h, 0 <= z <= 2.5 in sheared coordinates (u along the wall, w = across - z·tan a),
// a linear map that keeps the ray parameter, so a slab test solves the plane intersections.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/sensor/lidar.hpp"
#include "bvc3d/world/ray_caster.hpp"
#include "bvc3d/world/world.hpp"

using namespace bvc3d;

namespace {

constexpr double tol = 1e-6;
constexpr double inf = std::numeric_limits<double>::infinity();

Vec3 direction(double azimuth, double elevation) {
    return Vec3(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
}

// Entry distance of the ray into the box lo <= p <= hi (inf if it misses or starts inside).
double slab_entry(const Vec3& o, const Vec3& d, const Vec3& lo, const Vec3& hi) {
    double t0 = 0.0, t1 = inf;
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0.0) {
            if (o[k] < lo[k] || o[k] > hi[k]) return inf;
            continue;
        }
        double a = (lo[k] - o[k]) / d[k], b = (hi[k] - o[k]) / d[k];
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
    }
    return t0 <= t1 ? t0 : inf;
}

// Which surface the analytic ray met.
enum class Surface { outer, ceiling, floor, wall_a, wall_b };

struct Hit {
    double t = inf;
    Surface surface = Surface::outer;
};

Hit analytic_cross(const Vec3& o, const Vec3& d, double tilt_deg) {
    const double ta = std::tan(deg_to_rad(tilt_deg)), h = 0.15 / std::cos(deg_to_rad(tilt_deg));
    Hit best;
    auto consider = [&](double t, Surface s) {
        if (t < best.t) best = {t, s};
    };
    // Inside the 10 x 10 x 2.5 box: exit distance through each bounding plane.
    for (int k = 0; k < 2; ++k)
        if (d[k] != 0.0) consider(((d[k] > 0 ? 5.0 : -5.0) - o[k]) / d[k], Surface::outer);
    if (d.z() > 0) consider((2.5 - o.z()) / d.z(), Surface::ceiling);
    if (d.z() < 0) consider(-o.z() / d.z(), Surface::floor);
    // Wall A: u = x, w = y - z·tan a.   Wall B: u = y, w = x - z·tan a.
    const Vec3 oa(o.x(), o.y() - o.z() * ta, o.z()), da(d.x(), d.y() - d.z() * ta, d.z());
    const Vec3 ob(o.y(), o.x() - o.z() * ta, o.z()), db(d.y(), d.x() - d.z() * ta, d.z());
    const Vec3 lo(-3.5, -h, 0.0), hi(3.5, h, 2.5);
    consider(slab_entry(oa, da, lo, hi), Surface::wall_a);
    consider(slab_entry(ob, db, lo, hi), Surface::wall_b);
    return best;
}

class CrossArenaRays : public ::testing::TestWithParam<double> {};

}  // namespace

TEST_P(CrossArenaRays, DesignedRaysHitTheIntendedFace) {
    const double tilt = GetParam();
    const double ta = std::tan(deg_to_rad(tilt)), h = 0.15 / std::cos(deg_to_rad(tilt));
    const World world = World::cross({.tilt_deg = tilt});
    struct Case {
        Vec3 origin;
        double azimuth, elevation;
        Surface surface;
        double plane_t;  // the hand-solved distance to the intended plane, filled below
    };
    // Plane solves: outer x = 5 -> (5 - ox)/dx; ceiling -> (2.5 - oz)/dz;
    // wall A faces y - z·ta = ±h -> (±h - oy + oz·ta)/(dy - dz·ta); wall B likewise with x.
    auto wall_a = [&](const Vec3& o, const Vec3& d, double side) {
        return (side * h - o.y() + o.z() * ta) / (d.y() - d.z() * ta);
    };
    auto wall_b = [&](const Vec3& o, const Vec3& d, double side) {
        return (side * h - o.x() + o.z() * ta) / (d.x() - d.z() * ta);
    };
    std::vector<Case> cases;
    auto add = [&](Vec3 o, double az, double el, Surface s, double t) { cases.push_back({o, az, el, s, t}); };
    {
        const Vec3 o(-4.5, -4.5, 0.18);
        add(o, 0.0, 0.0, Surface::outer, 9.5);
        add(o, 0.05, 0.1, Surface::outer, (5.0 - o.x()) / direction(0.05, 0.1).x());
        add(Vec3(-4, -4, 0.18), -3 * pi / 4, 1.2, Surface::ceiling, 2.32 / std::sin(1.2));
        add(Vec3(-4, -4, 0.18), 0.3, pi / 2 - 0.01, Surface::ceiling, 2.32 / std::sin(pi / 2 - 0.01));
    }
    for (double el : {0.0, 0.3}) {
        // x < 0 and y < 0 keep wall B's and wall A's overhangs (toward +x, +y) out of the way.
        const Vec3 below(-2.0, -2.0, 0.18), above(-2.0, 3.0, 0.18);
        add(below, pi / 2, el, Surface::wall_a, wall_a(below, direction(pi / 2, el), -1));
        add(above, -pi / 2, el * 0.5, Surface::wall_a, wall_a(above, direction(-pi / 2, el * 0.5), +1));
        const Vec3 left(-2.0, -2.0, 0.18), right(3.0, -2.0, 0.18);
        add(left, 0.0, el, Surface::wall_b, wall_b(left, direction(0.0, el), -1));
        add(right, pi, el * 0.5, Surface::wall_b, wall_b(right, direction(pi, el * 0.5), +1));
    }
    for (const auto& c : cases) {
        const Vec3 d = direction(c.azimuth, c.elevation);
        const Hit oracle = analytic_cross(c.origin, d, tilt);
        // The case is valid only if the intended face is really the first surface on the ray.
        ASSERT_EQ(oracle.surface, c.surface) << "origin " << c.origin.transpose() << " az " << c.azimuth;
        ASSERT_NEAR(oracle.t, c.plane_t, 1e-12);
        EXPECT_NEAR(world.rays().cast(c.origin, d, 20.0), c.plane_t, tol)
            << "tilt " << tilt << " origin " << c.origin.transpose() << " az " << c.azimuth << " el " << c.elevation;
    }
}

TEST_P(CrossArenaRays, EveryBeamOfBothScannersMatchesTheAnalyticArena) {
    const double tilt = GetParam();
    const World world = World::cross({.tilt_deg = tilt});
    const Lidar spherical(LidarSpec::spherical(false)), horizontal(LidarSpec::horizontal());
    int walls_seen = 0;
    for (const Pose pose : {Pose::on_floor(4, 4, 0.3), Pose::on_floor(-1.2, 0.7, 2.0), Pose::on_floor(1.0, -2.5, -1.0),
                            Pose::on_floor(0.6, 4.6, 3.0)}) {
        for (const Lidar* lidar : {&spherical, &horizontal}) {
            const Scan scan = lidar->scan(world, pose);
            ASSERT_EQ(scan.size(), lidar->spec().beam_count()) << "a closed arena returns every beam";
            const Vec3 o(pose.x, pose.y, lidar->spec().height);
            for (const auto& r : scan) {
                const Hit oracle = analytic_cross(o, direction(r.azimuth, r.elevation), tilt);
                walls_seen += oracle.surface == Surface::wall_a || oracle.surface == Surface::wall_b;
                ASSERT_NEAR(r.range, oracle.t, tol) << "tilt " << tilt << " az " << r.azimuth << " el " << r.elevation;
            }
        }
    }
    EXPECT_GT(walls_seen, 1000);
}

TEST_P(CrossArenaRays, StraightUpUnderTheOverhang) {
    const double tilt = GetParam();
    if (tilt == 0.0) GTEST_SKIP() << "upright walls have no overhang";
    const double ta = std::tan(deg_to_rad(tilt)), h = 0.15 / std::cos(deg_to_rad(tilt));
    const World world = World::cross({.tilt_deg = tilt});
    // From (-2, 1.5), wall A's upper face y = z·tan(a) + h passes overhead at z = (1.5 - h)/tan(a).
    const double z_hit = (1.5 - h) / ta;
    const double expected = z_hit < 2.5 ? z_hit - 0.18 : 2.5 - 0.18;
    EXPECT_NEAR(world.rays().cast(Vec3(-2.0, 1.5, 0.18), Vec3::UnitZ(), 20.0), expected, tol);
}

INSTANTIATE_TEST_SUITE_P(PaperTilts, CrossArenaRays, ::testing::Values(0.0, 30.0, 45.0, 60.0));

TEST(CrossArena, LeanPicksTheCorner) {
    const double t = std::tan(deg_to_rad(45.0)), h = 0.15 / std::cos(deg_to_rad(45.0));
    // Looking straight up at (-2, -1.5): only a wall leaning toward -y (or -x) passes overhead.
    const World minus = World::cross({.tilt_deg = 45, .lean = "+x-y"});
    EXPECT_NEAR(minus.rays().cast(Vec3(-2.0, -1.5, 0.18), Vec3::UnitZ(), 20.0), (1.5 - h) / t - 0.18, tol);
    const World plus = World::cross({.tilt_deg = 45, .lean = "+x+y"});
    EXPECT_NEAR(plus.rays().cast(Vec3(-2.0, -1.5, 0.18), Vec3::UnitZ(), 20.0), 2.5 - 0.18, tol);
}

TEST(CrossArena, RejectsImpossibleParameters) {
    EXPECT_THROW(World::cross({.tilt_deg = 70}), InputError);
    EXPECT_THROW(World::cross({.tilt_deg = -5}), InputError);
    EXPECT_THROW(World::cross({.tilt_deg = NAN}), InputError);
    EXPECT_THROW(World::cross({.lean = "north"}), InputError);
}

TEST(RayCaster, MaxRangeAndMisses) {
    TriangleMesh m;
    m.add_quad(Vec3(5, -1, -1), Vec3(5, 1, -1), Vec3(5, 1, 1), Vec3(5, -1, 1));
    const RayCaster rc(m);
    EXPECT_NEAR(rc.cast(Vec3::Zero(), Vec3::UnitX(), 20.0), 5.0, 1e-12);
    EXPECT_EQ(rc.cast(Vec3::Zero(), Vec3::UnitX(), 4.999), RayCaster::no_hit);
    EXPECT_EQ(rc.cast(Vec3::Zero(), -Vec3::UnitX(), 20.0), RayCaster::no_hit);
    EXPECT_THROW(RayCaster(TriangleMesh{}), InputError);
}

namespace {
// Nearest intersection of the ray o + t·d (t >= 0, d unit) with a ball, from the textbook quadratic
// t² + 2(d·(o−c))t + |o−c|² − ρ² = 0; inf if none.
double analytic_sphere(const Vec3& o, const Vec3& d, const Vec3& c, double rho) {
    const Vec3 oc = o - c;
    const double half_b = d.dot(oc), cc = oc.dot(oc) - rho * rho;
    const double disc = half_b * half_b - cc;
    if (disc < 0) return inf;
    const double t1 = -half_b - std::sqrt(disc), t2 = -half_b + std::sqrt(disc);
    if (t1 >= 0) return t1;
    return t2 >= 0 ? t2 : inf;
}
}  // namespace

TEST(RayCaster, SpheresAreHitExactlyInDouble) {
    // A cloud of spheres in front of a wall: every ray's range equals the nearest analytic hit.
    std::vector<SphereSet> sets(2);
    sets[0].radius = 0.05;
    sets[1].radius = 0.2;
    std::uint64_t state = 12345;
    auto uniform = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<double>(state >> 11) / 9007199254740992.0;
    };
    for (int i = 0; i < 400; ++i)
        sets[0].centers.emplace_back(3 + 4 * uniform(), -3 + 6 * uniform(), -1 + 2 * uniform());
    for (int i = 0; i < 30; ++i)
        sets[1].centers.emplace_back(3 + 4 * uniform(), -3 + 6 * uniform(), -1 + 2 * uniform());
    TriangleMesh wall;
    wall.add_quad(Vec3(9, -20, -20), Vec3(9, 20, -20), Vec3(9, 20, 20), Vec3(9, -20, 20));
    const RayCaster rc(wall, sets);
    const Vec3 origin(0.1, 0.2, 0.05);
    int sphere_hits = 0;
    for (int i = 0; i < 4000; ++i) {
        const Vec3 d = direction(-0.6 + 1.2 * uniform(), -0.3 + 0.6 * uniform());
        double expected = (9.0 - origin.x()) / d.x();
        bool on_sphere = false;
        for (const auto& set : sets)
            for (const Vec3& c : set.centers) {
                const double t = analytic_sphere(origin, d, c, set.radius);
                if (t < expected) expected = t, on_sphere = true;
            }
        sphere_hits += on_sphere;
        ASSERT_NEAR(rc.cast(origin, d, 100.0), expected, 1e-9) << i;
    }
    EXPECT_GT(sphere_hits, 400);  // the test exercises spheres, not only the wall
    // From inside a sphere, the ray leaves through its far side.
    std::vector<SphereSet> one{{{Vec3(1, 0, 0)}, 0.5}};
    const RayCaster inside(TriangleMesh{}, one);
    EXPECT_NEAR(inside.cast(Vec3(1.2, 0, 0), Vec3::UnitX(), 10.0), 0.3, 1e-12);
    EXPECT_NEAR(inside.cast(Vec3(-1, 0, 0), Vec3::UnitX(), 10.0), 1.5, 1e-12);
    EXPECT_EQ(inside.cast(Vec3(-1, 0, 0), -Vec3::UnitX(), 10.0), RayCaster::no_hit);
    std::vector<SphereSet> bad{{{Vec3(1, 0, 0)}, 0.0}};
    EXPECT_THROW(RayCaster(TriangleMesh{}, bad), InputError);
}

TEST(World, PointCloudWorldScansAndBounds) {
    // A ring of spheres around the sensor at 4 m: a horizontal scanner sees it at 4 - radius.
    WorldDescription w;
    w.name = "ring";
    SphereSet ring;
    ring.radius = 0.1;
    for (int k = 0; k < 3600; ++k)
        ring.centers.emplace_back(4 * std::cos(k * two_pi / 3600), 4 * std::sin(k * two_pi / 3600), 0.08);
    w.spheres.push_back(ring);
    w.walkable = Polygon2::rectangle(-3, -3, 3, 3);
    EXPECT_TRUE(w.has_geometry());
    EXPECT_NEAR(w.bounds().max().x(), 4.1, 1e-12);
    const World world(w);
    const Scan s = Lidar(LidarSpec::horizontal()).scan(world, Pose::on_floor(0, 0, 0.3));
    ASSERT_EQ(s.size(), 720u);
    for (const auto& r : s) ASSERT_NEAR(r.range, 3.9, 1e-3);  // between sphere centers the ring is slightly deeper
}

TEST(World, CopiesOutliveTheOriginalWithSpheres) {
    // Copies of a World share its caster: the caster must not point into the original's data.
    std::optional<World> copy;
    {
        WorldDescription w;
        w.name = "one";
        w.spheres.push_back(SphereSet{{Vec3(2, 0, 0)}, 0.5});
        w.walkable = Polygon2::rectangle(-1, -1, 1, 1);
        const World original(w);
        copy.emplace(original);
    }
    EXPECT_NEAR(copy->rays().cast(Vec3::Zero(), Vec3::UnitX(), 10.0), 1.5, 1e-12);
}

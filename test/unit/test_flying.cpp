// The flying agent (docs/flying.md#the-flying-agent): its body never overlaps geometry nor leaves the
// flight volume at any speed (checked against an oracle that shares no code with the collider), its
// turns follow their distributions, time counts motion and turns, it covers the flight volume, it
// is deterministic by seed and resumes from its state; bad worlds and mismatched presets are errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>
#include <tuple>

#include "../support/ks_test.hpp"
#include "../support/sphere_oracle.hpp"
#include "bvc3d/agent/flying_walk.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/config/trial_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"

using namespace bvc3d;

namespace {

constexpr double R = 0.2;

std::vector<oracle::Triangle> triangles_of(const WorldDescription& w) {
    std::vector<oracle::Triangle> out;
    for (std::size_t t = 0; t < w.mesh.size(); ++t) {
        const auto c = w.mesh.corners(t);
        out.push_back({{c[0].x(), c[0].y(), c[0].z()}, {c[1].x(), c[1].y(), c[1].z()}, {c[2].x(), c[2].y(), c[2].z()}});
    }
    return out;
}

// How far the body's center is inside the flight volume's box shrunk by R (< 0: outside). All the
// flight worlds' regions are rectangles.
double inside_margin(const FlightVolume& v, const Vec3& p) {
    const auto b = v.bounds();
    double m = INFINITY;
    for (int d = 0; d < 3; ++d) m = std::min({m, p[d] - (b.min()[d] + R), (b.max()[d] - R) - p[d]});
    return m;
}

using reference::ks_critical_1pct;
using reference::ks_statistic;
using reference::normal_cdf;

FlightParams body_head() {
    FlightParams p;
    p.head = FlightHead::body;  // poses carry the pitch, so the test can read the turns off them
    return p;
}

class FlightWorlds : public ::testing::TestWithParam<const char*> {};

}  // namespace

TEST_P(FlightWorlds, EightHoursNeverOverlapNorLeaveTheVolume) {
    const World world(config::resolve_world(GetParam()));
    const auto& volume = *world.description().flight;
    const auto tris = triangles_of(world.description());
    const auto steps = flying_walk(world, 8.0, 21, body_head());
    ASSERT_GT(steps.size(), 40000u);
    double worst_overlap = INFINITY, worst_inside = INFINITY;
    auto check = [&](const Vec3& p) {
        worst_overlap = std::min(worst_overlap, oracle::nearest({p.x(), p.y(), p.z()}, tris) - R);
        worst_inside = std::min(worst_inside, inside_margin(volume, p));
    };
    std::size_t segments = 0;
    for (std::size_t i = 0; i < steps.size(); ++i) {
        const Pose& q = steps[i].pose;
        check(q.position());
        // Along the straight path from the previous step (same direction, no turn in between).
        if (i > 0 && !steps[i - 1].bumped && steps[i - 1].pose.heading == q.heading &&
            steps[i - 1].pose.pitch == q.pitch) {
            ++segments;
            const Vec3 a = steps[i - 1].pose.position();
            for (int k = 1; k < 12; ++k) check(a + (k / 12.0) * (q.position() - a));
        }
    }
    EXPECT_GT(segments, steps.size() / 2);
    EXPECT_GE(worst_overlap, -1e-6) << "the body overlapped geometry by " << -worst_overlap << " m";
    EXPECT_LT(worst_overlap, 1e-6) << "bumps should bring the body into contact";
    EXPECT_GE(worst_inside, -1e-6) << "the body left the flight volume by " << -worst_inside << " m";
    // The last step ends within a few turns of the end (a bump turns by up to (pi + 2 pi/3) / 2.1 s,
    // and a corner may need several draws).
    EXPECT_LE(steps.back().t, 8 * 3600.0 + 0.288);  // a step begun before the end finishes
    EXPECT_GT(steps.back().t, 8 * 3600.0 - 15.0);
}

TEST_P(FlightWorlds, ADefaultTrialsFlightVisitsEveryReachableHalfMetreVoxel) {
    // A default trial's flight (8 h exploration + 8 h sampling) covers the flight volume.
    const World world(config::resolve_world(GetParam()));
    const auto& w = world.description();
    const auto tris = triangles_of(w);
    const auto steps = flying_walk(world, 16.0, 5);
    const auto box = w.flight->bounds();
    std::set<std::tuple<int, int, int>> visited;
    auto voxel = [&](const Vec3& p, int d) { return static_cast<int>(std::floor((p[d] - box.min()[d]) / 0.5)); };
    for (const auto& s : steps)
        visited.insert({voxel(s.pose.position(), 0), voxel(s.pose.position(), 1), voxel(s.pose.position(), 2)});
    // A voxel is reachable if the body's center fits with 2 cm to spare at a quarter or more of a
    // 6 × 6 × 6 lattice of points in it (slivers beside a pillar or under a leaning wall are visited
    // only by grazing contacts), inside the volume and outside the pillars (solid boxes the oracle
    // knows: the atrium's two 0.6 m pillars).
    auto in_pillar = [&](const Vec3& p) {
        if (w.name != "atrium") return false;
        for (const auto& c : {Vec2(-1.5, 1.0), Vec2(2.0, -1.5)})
            if (std::abs(p.x() - c.x()) < 0.3 && std::abs(p.y() - c.y()) < 0.3) return true;
        return false;
    };
    const int nx = static_cast<int>(std::ceil(box.sizes().x() / 0.5)),
              ny = static_cast<int>(std::ceil(box.sizes().y() / 0.5)),
              nz = static_cast<int>(std::ceil(box.sizes().z() / 0.5));
    int reachable = 0, missed = 0;
    for (int i = 0; i < nx; ++i)
        for (int j = 0; j < ny; ++j)
            for (int k = 0; k < nz; ++k) {
                int fits = 0;
                for (int a = 0; a <= 5; ++a)
                    for (int b = 0; b <= 5; ++b)
                        for (int c = 0; c <= 5; ++c) {
                            const Vec3 p = box.min() + Vec3(0.5 * i + 0.1 * a, 0.5 * j + 0.1 * b, 0.5 * k + 0.1 * c);
                            fits += inside_margin(*w.flight, p) >= 0.02 && !in_pillar(p) &&
                                    oracle::nearest({p.x(), p.y(), p.z()}, tris) - R >= 0.02;
                        }
                if (4 * fits < 216) continue;
                ++reachable;
                if (!visited.count({i, j, k})) {
                    ++missed;
                    ADD_FAILURE() << GetParam() << ": voxel at " << (box.min() + 0.5 * Vec3(i, j, k)).transpose()
                                  << " never visited";
                }
            }
    EXPECT_GT(reachable, 100);
    EXPECT_EQ(missed, 0);
}

INSTANTIATE_TEST_SUITE_P(Worlds, FlightWorlds, ::testing::Values("flight-room", "atrium", "cross-0", "cross-60"),
                         [](const auto& param_info) {
                             std::string s = param_info.param;
                             std::replace(s.begin(), s.end(), '-', '_');
                             return s;
                         });

namespace {

// A 6 × 2 × 2 m room cut in two by a wall of zero thickness at x = 0 (y in [-1, wall_top_y]).
WorldDescription thin_wall_world(double wall_y1 = 1.0) {
    WorldDescription w;
    w.name = "thin-wall";
    w.mesh.append(box_mesh(Vec3(6, 2, 2)), Eigen::Isometry3d(Eigen::Translation3d(0, 0, 1)));
    w.mesh.add_quad(Vec3(0, -1, 0), Vec3(0, wall_y1, 0), Vec3(0, wall_y1, 2), Vec3(0, -1, 2));
    w.flight = FlightVolume{Polygon2::rectangle(-3, -1, 3, 1), 0.0, 2.0};
    return w;
}

}  // namespace

TEST(SphereCollider, ExactContactDistances) {
    const SphereCollider body(thin_wall_world(0.5), R);
    // Head-on into the wall's face from x = -2: contact when the center reaches x = -R.
    EXPECT_NEAR(body.free_distance(Vec3(-2, 0, 1), Vec3(1, 0, 0), 10.0), 2 - R, 1e-12);
    // Along a diagonal in the xz plane: the face is reached after (2 - R) / cos 30°.
    const Vec3 diag(std::cos(pi / 6), 0, std::sin(pi / 6));
    EXPECT_NEAR(body.free_distance(Vec3(-2, 0, 0.5), diag, 10.0), (2 - R) / std::cos(pi / 6), 1e-12);
    // Past the wall's free edge (y = 0.5) at y = 0.6: the edge's cylinder, where hypot(x, 0.1) = R.
    EXPECT_NEAR(body.free_distance(Vec3(-2, 0.6, 1), Vec3(1, 0, 0), 10.0), 2 - std::sqrt(R * R - 0.01), 1e-12);
    // At y = 0.75 it passes, and the room's end wall at x = 3 stops it (the volume too).
    EXPECT_NEAR(body.free_distance(Vec3(-2, 0.75, 1), Vec3(1, 0, 0), 10.0), 5 - R, 1e-12);
    // The wall's top corner (0, 0.5, 2) lies in the ceiling; a vertex of the volume's floor: straight
    // down onto the volume's floor z = 0.
    EXPECT_NEAR(body.free_distance(Vec3(-1, 0, 1.5), Vec3(0, 0, -1), 10.0), 1.5 - R, 1e-12);
    EXPECT_NEAR(body.clearance(Vec3(-1, 0, 1)), 0.8, 1e-12);  // nearest: the walls y = ±1, the wall x = 0
    // Touching and moving into the contact: blocked; moving away: free.
    EXPECT_EQ(body.free_distance(Vec3(-R + 1e-12, 0, 1), Vec3(1, 0, 0), 1.0), 0.0);
    EXPECT_EQ(body.free_distance(Vec3(-R + 1e-12, 0, 1), Vec3(-1, 0, 0), 1.0), 1.0);
    EXPECT_TRUE(body.is_free(Vec3(-1, 0, 1)));
    EXPECT_FALSE(body.is_free(Vec3(-0.1, 0, 1)));
    EXPECT_FALSE(body.is_free(Vec3(-1, 0, 0.1)));  // below z_min + R
}

TEST(SphereCollider, AVertexStopsTheBodyWhereTheBallAroundItIsEntered) {
    WorldDescription w;
    w.name = "spike";
    w.mesh.append(box_mesh(Vec3(10, 10, 10)));
    w.mesh.add_triangle(Vec3(0, 0, 0), Vec3(1, 0.5, 0), Vec3(1, -0.5, 0));  // its vertex (0, 0, 0) points at -x
    w.flight = FlightVolume{Polygon2::rectangle(-5, -5, 5, 5), -5, 5};
    const SphereCollider body(w, R);
    // From (-3, 0.1, 0.1) along +x: the ball of radius R around the vertex is entered where
    // x² + 0.02 = R², i.e. after 3 - sqrt(R² - 0.02).
    EXPECT_NEAR(body.free_distance(Vec3(-3, 0.1, 0.1), Vec3(1, 0, 0), 10.0), 3 - std::sqrt(R * R - 0.02), 1e-12);
}

TEST(FlyingWalk, NoTunnelingThroughAThinWallAtAnySpeed) {
    const World world(thin_wall_world());
    FlightParams fast;
    fast.speed = 1000.0;  // 288 m per model step, 48 times the room's length
    fast.turn_rate = 1e6;
    for (std::uint64_t seed = 0; seed < 6; ++seed) {
        const auto steps = flying_walk(world, 0.05, seed, fast);
        ASSERT_GT(steps.size(), 100u);
        const double side = steps.front().pose.x > 0 ? 1 : -1;
        for (const auto& s : steps) {
            ASSERT_GE(side * s.pose.x, R - 1e-6) << "seed " << seed << " crossed the wall at t = " << s.t;
            ASSERT_LE(std::abs(s.pose.x), 3 - R + 1e-6);
        }
    }
}

TEST(FlyingWalk, TurnsFollowTheirDistributions) {
    const World world(config::resolve_world("atrium"));
    const FlightParams p = body_head();
    auto body = std::make_shared<const SphereCollider>(world.description(), p.radius);
    Rng rng(2024, Stream::walk);
    const FlightState start = FlyingWalk::draw_start(*body, p, rng, "atrium");
    FlyingWalk walk(body, p, rng, start);
    std::vector<FlightTurn> log;
    walk.log_turns(&log);
    std::vector<ModelStep> steps;
    while (auto s = walk.next(12 * 3600.0)) steps.push_back(*s);

    // Realized yaw turns after n_walk uninterrupted steps, read off the trajectory: N(0, (π/6)²).
    std::vector<double> yaw_turns, pitch_draws, bump_yaw, bump_sin_pitch;
    for (std::size_t i = 0; i + 1 < steps.size(); ++i)
        if (!steps[i].bumped && steps[i + 1].pose.heading != steps[i].pose.heading)
            yaw_turns.push_back(wrap_pi(steps[i + 1].pose.heading - steps[i].pose.heading));
    ASSERT_GT(yaw_turns.size(), 5000u);
    EXPECT_LT(ks_statistic(yaw_turns, [](double x) { return normal_cdf(x, pi / 6); }),
              ks_critical_1pct(yaw_turns.size()));
    // Pitch turns as drawn (the realized ones are clipped to ±π/3): N(0, (π/12)²).
    for (const auto& e : log)
        if (e.kind == FlightTurn::Kind::gaussian) pitch_draws.push_back(e.pitch);
        else bump_yaw.push_back(e.yaw), bump_sin_pitch.push_back(std::sin(e.pitch));
    ASSERT_GT(pitch_draws.size(), 5000u);
    EXPECT_LT(ks_statistic(pitch_draws, [](double x) { return normal_cdf(x, pi / 12); }),
              ks_critical_1pct(pitch_draws.size()));
    // After a bump: uniform on the sphere within the pitch limits, so yaw uniform on [-π, π) and
    // sin(pitch) uniform on [-sin π/3, sin π/3].
    ASSERT_GT(bump_yaw.size(), 1000u);
    EXPECT_LT(ks_statistic(bump_yaw, [](double x) { return (x + pi) / two_pi; }), ks_critical_1pct(bump_yaw.size()));
    const double s = std::sin(pi / 3);
    EXPECT_LT(ks_statistic(bump_sin_pitch, [s](double x) { return (x + s) / (2 * s); }),
              ks_critical_1pct(bump_sin_pitch.size()));
    // The realized pitch never leaves its limits.
    for (const auto& st : steps) ASSERT_LE(std::abs(st.pose.pitch), pi / 3 + 1e-15);
}

TEST(FlyingWalk, SimulatedTimeCountsMotionAndBothTurns) {
    const World world(config::resolve_world("atrium"));
    const FlightParams p = body_head();
    const auto steps = flying_walk(world, 2.0, 3, p);
    std::size_t turned = 0, mismatched = 0, moved = 0;
    for (std::size_t i = 0; i + 1 < steps.size(); ++i) {
        const auto &a = steps[i], &b = steps[i + 1];
        if (a.bumped || b.bumped) continue;
        const double turn = std::abs(wrap_pi(b.pose.heading - a.pose.heading)) + std::abs(b.pose.pitch - a.pose.pitch);
        // A step of 0.288 m takes 0.288 s; a turn |Δyaw|/2.1 + |Δpitch|/2.1. (A turn into a wall adds an
        // unrecorded bump in between: rare.)
        if (std::abs((b.t - a.t) - (p.model_dt + turn / p.turn_rate)) > 1e-9) {
            ++mismatched;
            continue;
        }
        turned += turn > 0;
        ++moved;
        EXPECT_NEAR((b.pose.position() - a.pose.position()).norm(), 0.288, 1e-12);
    }
    EXPECT_LT(mismatched, steps.size() / 200);
    EXPECT_GT(turned, 500u);
    EXPECT_GT(moved, steps.size() / 2);
    // A step cut short by a bump takes the time of the distance it moved.
    std::size_t bumps = 0;
    for (std::size_t i = 0; i + 1 < steps.size(); ++i) {
        const auto &a = steps[i], &b = steps[i + 1];
        if (!b.bumped || a.bumped || a.pose.heading != b.pose.heading || a.pose.pitch != b.pose.pitch) continue;
        ++bumps;
        const double d = (b.pose.position() - a.pose.position()).norm();
        EXPECT_GT(d, 1e-3);
        EXPECT_LT(d, 0.288);
        EXPECT_NEAR(b.t - a.t, d / p.speed, 1e-9);
    }
    EXPECT_GT(bumps, 100u);
}

TEST(FlyingWalk, LevelHeadByDefaultAndStartsAnywhereInTheVolume) {
    const World world(config::resolve_world("atrium"));
    const auto steps = flying_walk(world, 0.5, 8);
    for (const auto& s : steps) ASSERT_TRUE(s.pose.level());
    // Starts: uniform in the volume, never inside a pillar. Drawn as a walk of each seed draws its start, on one
    // body (building the body's free space once per walk made this test minutes long under the sanitizers).
    const SphereCollider body(world.description(), R);
    double lo = INFINITY, hi = -INFINITY;
    for (std::uint64_t seed = 0; seed < 60; ++seed) {
        Rng rng(seed, Stream::walk);
        const Vec3 p = FlyingWalk::draw_start(body, FlightParams{}, rng, "atrium").position;
        lo = std::min(lo, p.z()), hi = std::max(hi, p.z());
        for (const auto& c : {Vec2(-1.5, 1.0), Vec2(2.0, -1.5)})
            EXPECT_GT(std::max(std::abs(p.x() - c.x()), std::abs(p.y() - c.y())), 0.3 + R - 0.3) << seed;
    }
    EXPECT_LT(lo, 2.0);
    EXPECT_GT(hi, 3.5);
    // A walk of that seed starts there: its first step lies within one step's flight (0.288 m) of the drawn start.
    ASSERT_EQ(FlightParams{}.radius, R);
    const auto first = flying_walk(world, 0.0005, 7);
    Rng rng7(7, Stream::walk);
    ASSERT_FALSE(first.empty());
    const Vec3 start = FlyingWalk::draw_start(body, FlightParams{}, rng7, "atrium").position;
    EXPECT_LE((first[0].pose.position() - start).norm(), FlightParams{}.speed * FlightParams{}.model_dt + 1e-9);
    EXPECT_TRUE(body.is_free(Vec3(-1.5, 1.0, 1.0)));        // inside the pillar, far from its faces ...
    EXPECT_FALSE(body.can_start_at(Vec3(-1.5, 1.0, 1.0)));  // ... but closed off
    EXPECT_TRUE(body.can_start_at(Vec3(0, 0, 1.0)));
}

TEST(FlyingWalk, SameSeedSameFlightAndResumesFromItsState) {
    const World world(config::resolve_world("cross-60"));
    const auto a = flying_walk(world, 0.5, 42), b = flying_walk(world, 0.5, 42), c = flying_walk(world, 0.5, 43);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i].t, b[i].t);
        ASSERT_EQ(a[i].pose.position(), b[i].pose.position());
        ASSERT_EQ(a[i].pose.heading, b[i].pose.heading);
        ASSERT_EQ(a[i].bumped, b[i].bumped);
    }
    EXPECT_TRUE(a.size() != c.size() || a[5].pose.x != c[5].pose.x);

    const auto spec = FlightSpec();
    auto full = spec.make(&world, 9), part = spec.make(&world, 9);
    std::vector<ModelStep> x, y;
    while (auto s = full->next(1800)) x.push_back(*s);
    while (auto s = part->next(900)) y.push_back(*s);
    auto resumed = spec.make(&world, 0);
    resumed->restore_state(part->save_state());
    while (auto s = resumed->next(1800)) y.push_back(*s);
    ASSERT_EQ(x.size(), y.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
        ASSERT_EQ(x[i].pose.position(), y[i].pose.position()) << i;
        ASSERT_EQ(x[i].t, y[i].t) << i;
    }
    EXPECT_THROW(resumed->restore_state("random_walk 1 2 3 4 0 0\n"), InputError);
}

namespace {

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

std::string world_yaml_error(const std::string& flight_volume) {
    return error_of([&] {
        config::world_from_yaml(config::YamlView::load_string(
            "name: w\nobjects:\n  - box: {center: [0, 0, 1], size: [4, 4, 2]}\nflight_volume: " + flight_volume + "\n",
            "w.yaml"));
    });
}

}  // namespace

TEST(FlightErrors, BadFlightVolumesSayWhatIsWrong) {
    // Empty, outside the world, smaller than the body.
    EXPECT_NE(world_yaml_error("{rect: [-1, -1, 1, 1], z_min: 1, z_max: 1}").find("is empty"), std::string::npos);
    EXPECT_NE(world_yaml_error("{rect: [-1, -1, 1, 1], z_min: 1, z_max: 0.5}").find("is empty"), std::string::npos);
    const auto outside = world_yaml_error("{rect: [-1, -1, 5, 1], z_min: 0.5, z_max: 1.5}");
    EXPECT_NE(outside.find("w.yaml"), std::string::npos) << outside;
    EXPECT_NE(outside.find("flight_volume"), std::string::npos) << outside;
    EXPECT_NE(outside.find("outside the world"), std::string::npos) << outside;
    EXPECT_NE(world_yaml_error("{rect: [-1, -1, 1, 1], z_min: 0.5, z_max: 3}").find("outside the world"),
              std::string::npos);
    EXPECT_NE(world_yaml_error("{z_min: 0.5, z_max: 1.5}").find("'rect' or 'polygon'"), std::string::npos);
    WorldDescription small = config::world_from_yaml(config::YamlView::load_string(
        "name: w\nobjects:\n  - box: {center: [0, 0, 1], size: [4, 4, 2]}\nflight_volume: {rect: [-1, -1, 1, 1], "
        "z_min: 0.5, z_max: 0.8}\n",
        "w.yaml"));
    const auto too_small = error_of([&] { flying_walk(World(small), 0.1, 0); });
    EXPECT_NE(too_small.find("smaller than the body"), std::string::npos) << too_small;
}

TEST(FlightErrors, AgentsAndPresetsOfTheOtherKind) {
    // A ground world with a flying agent, a flight-only world with the ground robot.
    const auto ground = error_of(
        [] { flying_walk(World(config::load_world_file(BVC3D_SOURCE_DIR "/configs/worlds/two-rooms.yaml")), 0.1, 0); });
    EXPECT_NE(ground.find("no flight volume"), std::string::npos) << ground;
    const auto flight_only = error_of([] { random_walk(World(flight_room()), 0.1, 0); });
    EXPECT_NE(flight_only.find("flight-only world"), std::string::npos) << flight_only;
    // A ground model preset on a flying agent and the reverse, from trial YAML.
    auto trial_error = [](const std::string& text) {
        return error_of([&] { config::trial_from_yaml(config::YamlView::load_string(text, "t.yaml")).validate(); });
    };
    const auto ground_model = trial_error("world: flight-room\nmodel: 3d-0.2\nflight: {}\n");
    EXPECT_NE(ground_model.find("preset for the ground robot"), std::string::npos) << ground_model;
    const auto flying_model = trial_error("world: cross\nmodel: fly-5l\n");
    EXPECT_NE(flying_model.find("preset for flying agents"), std::string::npos) << flying_model;
    EXPECT_EQ(trial_error("world: flight-room\nmodel: fly-5l\nflight: {radius: 0.3}\n"), "(no error)");
    const auto both = trial_error("world: cross\nmodel: fly-5l\nflight: {}\nrobot: {}\n");
    EXPECT_NE(both.find("not several"), std::string::npos) << both;
}

TEST(FlightWorldsYaml, PresetsEqualTheirFiles) {
    for (const std::string name : {"flight-room", "atrium"}) {
        const WorldDescription preset = config::resolve_world(name);
        const WorldDescription file = config::load_world_file(BVC3D_SOURCE_DIR "/configs/worlds/" + name + ".yaml");
        ASSERT_EQ(preset.mesh.size(), file.mesh.size()) << name;
        for (std::size_t t = 0; t < preset.mesh.size(); ++t)
            for (int k = 0; k < 3; ++k)
                ASSERT_EQ(preset.mesh.corners(t)[k], file.mesh.corners(t)[k]) << name << " " << t;
        ASSERT_TRUE(preset.flight && file.flight);
        EXPECT_EQ(preset.flight->bounds().min(), file.flight->bounds().min());
        EXPECT_EQ(preset.flight->bounds().max(), file.flight->bounds().max());
        EXPECT_TRUE(file.walkable.points.empty());
    }
    // The cross arenas carry a flight volume 0.2 m from floor and ceiling.
    const auto cross = config::resolve_world("cross-45");
    ASSERT_TRUE(cross.flight);
    EXPECT_EQ(cross.flight->z_min, 0.2);
    EXPECT_EQ(cross.flight->z_max, 2.3);
}

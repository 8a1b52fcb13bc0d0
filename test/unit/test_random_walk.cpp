// The robot's random walk (docs/model-reference.md#robot-and-random-walk): stays in the arena, never overlaps a wall,
// turns as specified, covers the floor, and is deterministic by seed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "../support/ks_test.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/uniform_point.hpp"

using namespace bvc3d;

namespace {

constexpr double R = 0.25;

// Independent oracle: the central walls' footprints over the body's height z in [0, 0.1] are the
// rectangles |x| <= 3.5, y in [-h, h + 0.1·tan a] (wall A, leaning +y) and the same with x, y swapped.
double distance_to_rect(double x, double y, double x0, double x1, double y0, double y1) {
    const double dx = std::max({x0 - x, 0.0, x - x1});
    const double dy = std::max({y0 - y, 0.0, y - y1});
    return std::hypot(dx, dy);
}

// Distance from the body's center to the nearest geometry minus the radius (negative: overlap).
double oracle_clearance(double x, double y, double tilt_deg) {
    const double a = deg_to_rad(tilt_deg), h = 0.15 / std::cos(a), reach = h + 0.1 * std::tan(a);
    double d = std::min({5 - x, 5 + x, 5 - y, 5 + y});
    d = std::min(d, distance_to_rect(x, y, -3.5, 3.5, -h, reach));
    d = std::min(d, distance_to_rect(x, y, -h, reach, -3.5, 3.5));
    return d - R;
}

using reference::ks_critical_1pct;
using reference::ks_statistic;
using reference::normal_cdf;

class PaperWorldWalk : public ::testing::TestWithParam<double> {};

}  // namespace

TEST_P(PaperWorldWalk, TwentyFourHoursNeverLeaveNorOverlap) {
    const double tilt = GetParam();
    const World world = World::cross({.tilt_deg = tilt});
    const auto steps = random_walk(world, 24.0, 11);
    ASSERT_GT(steps.size(), 200000u);
    double worst = INFINITY;
    for (std::size_t i = 0; i < steps.size(); ++i) {
        const auto& s = steps[i];
        ASSERT_LE(std::max(std::abs(s.pose.x), std::abs(s.pose.y)), 5.0 - R + 1e-9) << "left the arena at step " << i;
        worst = std::min(worst, oracle_clearance(s.pose.x, s.pose.y, tilt));
        // Along the straight path from the previous step (a step moves at most 0.144 m).
        if (i > 0 && steps[i - 1].pose.heading == s.pose.heading)
            for (int k = 1; k < 15; ++k) {
                const double f = k / 15.0;
                worst =
                    std::min(worst, oracle_clearance(steps[i - 1].pose.x + f * (s.pose.x - steps[i - 1].pose.x),
                                                     steps[i - 1].pose.y + f * (s.pose.y - steps[i - 1].pose.y), tilt));
            }
    }
    EXPECT_GE(worst, -1e-3) << "the body overlapped a wall by " << -worst << " m";
    EXPECT_LT(worst, 1e-6) << "bumps should bring the body into contact";
    EXPECT_NEAR(steps.back().t, 24 * 3600.0, 1.0);
}

TEST_P(PaperWorldWalk, FourHoursCoverEveryReachableHalfMetreCell) {
    const double tilt = GetParam();
    const World world = World::cross({.tilt_deg = tilt});
    const auto steps = random_walk(world, 4.0, 5);
    // 30-50 thousand samples per 4-hour phase (docs/model-reference.md#trial-protocol).
    EXPECT_GT(steps.size(), 30000u);
    EXPECT_LT(steps.size(), 50000u);
    std::set<std::pair<int, int>> visited;
    for (const auto& s : steps)
        visited.insert({static_cast<int>(std::floor(s.pose.x / 0.5)), static_cast<int>(std::floor(s.pose.y / 0.5))});
    // A cell is reachable if the body fits somewhere in it with 2 cm to spare (a sliver thinner than
    // that is visited only by grazing contacts, which a finite walk need not make).
    int reachable = 0;
    for (int cx = -10; cx < 10; ++cx)
        for (int cy = -10; cy < 10; ++cy) {
            bool fits = false;
            for (int i = 0; i <= 50 && !fits; ++i)
                for (int j = 0; j <= 50 && !fits; ++j)
                    fits = oracle_clearance(0.5 * cx + 0.01 * i, 0.5 * cy + 0.01 * j, tilt) >= 0.02;
            if (!fits) continue;
            ++reachable;
            EXPECT_TRUE(visited.count({cx, cy})) << "cell [" << 0.5 * cx << ", " << 0.5 * cy << "] never visited";
        }
    EXPECT_GT(reachable, 300);
}

INSTANTIATE_TEST_SUITE_P(PaperTilts, PaperWorldWalk, ::testing::Values(0.0, 30.0, 45.0, 60.0));

TEST(UniformPoint, DrawsTheLastAxisFirstWhateverTheCompiler) {
    // The same stream drawn by hand: z, then y, then x (y, then x in the plane), each scaled to its side.
    const Eigen::AlignedBox3d box(Vec3(-1, 2, 0.5), Vec3(3, 4, 2.5));
    Rng drawn(7, Stream::walk), by_hand(7, Stream::walk);
    const Vec3 p = uniform_point(box, drawn);
    const double z = by_hand.uniform(), y = by_hand.uniform(), x = by_hand.uniform();
    EXPECT_EQ(p, Vec3(-1 + 4 * x, 2 + 2 * y, 0.5 + 2 * z));
    const Vec2 q = uniform_point(Eigen::AlignedBox2d(Vec2(0, 0), Vec2(1, 1)), drawn);
    const double qy = by_hand.uniform(), qx = by_hand.uniform();
    EXPECT_EQ(q, Vec2(qx, qy));
}

TEST(RandomWalk, TurnsFollowTheirDistributions) {
    const World world = World::cross({.tilt_deg = 45});
    auto body = std::make_shared<const BodyCollider>(world.description(), R, 0.1);
    Rng rng(2024, Stream::walk);
    const Pose start = RandomWalk::draw_start(world.description(), *body, rng);
    RandomWalk walk(body, RobotParams{}, rng, start);
    std::vector<TurnEvent> log;
    walk.log_turns(&log);
    std::vector<ModelStep> steps;
    while (auto s = walk.next(8 * 3600.0)) steps.push_back(*s);

    // Realised turns after tau_w uninterrupted steps, read off the trajectory: N(0, (pi/6)^2).
    std::vector<double> gaussian_turns;
    for (std::size_t i = 0; i + 1 < steps.size(); ++i)
        if (!steps[i].bumped && steps[i + 1].pose.heading != steps[i].pose.heading)
            gaussian_turns.push_back(wrap_pi(steps[i + 1].pose.heading - steps[i].pose.heading));
    ASSERT_GT(gaussian_turns.size(), 5000u);
    const double d_gauss = ks_statistic(gaussian_turns, [](double x) { return normal_cdf(x, pi / 6); });
    EXPECT_LT(d_gauss, ks_critical_1pct(gaussian_turns.size()));

    // Headings drawn after bumps (including redraws when blocked at once): uniform on [-pi, pi).
    std::vector<double> bump_headings;
    for (const auto& e : log)
        if (e.kind == TurnEvent::Kind::bump) bump_headings.push_back(e.drawn);
    ASSERT_GT(bump_headings.size(), 1000u);
    const double d_unif = ks_statistic(bump_headings, [](double x) { return (x + pi) / two_pi; });
    EXPECT_LT(d_unif, ks_critical_1pct(bump_headings.size()));
    // ... and a bumped step is followed by the heading the last bump drew.
    std::size_t checked = 0;
    for (std::size_t i = 0; i + 1 < steps.size(); ++i)
        if (steps[i].bumped) ++checked;
    EXPECT_GT(checked, 1000u);
}

TEST(RandomWalk, SimulatedTimeCountsMotionAndTurns) {
    const World world = World::cross({.tilt_deg = 30});
    const auto steps = random_walk(world, 2.0, 3);
    RobotParams p;
    std::size_t turned = 0, mismatched = 0;
    int since_turn = 0;  // uninterrupted model steps since the last turn or bump
    for (std::size_t i = 0; i + 1 < steps.size(); ++i) {
        const auto &a = steps[i], &b = steps[i + 1];
        since_turn = a.bumped ? 0 : since_turn + 1;
        if (a.bumped || b.bumped) continue;
        const bool turn = a.pose.heading != b.pose.heading;
        const double expect = p.model_dt + std::abs(wrap_pi(b.pose.heading - a.pose.heading)) / p.turn_rate;
        // A turn comes exactly after n_walk uninterrupted steps, and its duration is |angle| / 2.1 rad/s.
        // (A turn that runs into a wall at once adds an unrecorded bump in between: rare.)
        if (std::abs((b.t - a.t) - expect) > 1e-9 || turn != (since_turn == p.n_walk)) {
            ++mismatched;
        } else {
            turned += turn;
            EXPECT_NEAR(std::hypot(b.pose.x - a.pose.x, b.pose.y - a.pose.y), 0.144, 1e-12);
        }
        if (turn) since_turn = 0;
    }
    EXPECT_LT(mismatched, steps.size() / 500);
    EXPECT_GT(turned, 1000u);
    // A step cut short by a bump takes the time of the distance it moved.
    std::size_t bumps = 0;
    for (std::size_t i = 0; i + 1 < steps.size(); ++i) {
        const auto &a = steps[i], &b = steps[i + 1];
        if (!b.bumped || a.bumped || a.pose.heading != b.pose.heading) continue;
        ++bumps;
        const double moved = std::hypot(b.pose.x - a.pose.x, b.pose.y - a.pose.y);
        EXPECT_GT(moved, 1e-3);
        EXPECT_LT(moved, 0.144);
        EXPECT_NEAR(b.t - a.t, moved / p.speed, 1e-9);
    }
    EXPECT_GT(bumps, 100u);
}

TEST(RandomWalk, StartsAtARandomCornerWithARandomHeading) {
    const World world = World::cross();
    std::set<std::pair<int, int>> corners;
    for (std::uint64_t seed = 0; seed < 40; ++seed) {
        const auto s = random_walk(world, 0.001, seed);
        ASSERT_FALSE(s.empty());
        corners.insert({s[0].pose.x > 0 ? 1 : -1, s[0].pose.y > 0 ? 1 : -1});
        EXPECT_LT(std::hypot(std::abs(s[0].pose.x) - 4.0, std::abs(s[0].pose.y) - 4.0), 0.15);
    }
    EXPECT_EQ(corners.size(), 4u);
}

TEST(RandomWalk, SameSeedSameTrajectoryDifferentSeedDifferent) {
    const World world = World::cross({.tilt_deg = 60});
    const auto a = random_walk(world, 0.5, 42), b = random_walk(world, 0.5, 42), c = random_walk(world, 0.5, 43);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i].t, b[i].t);
        ASSERT_EQ(a[i].pose.x, b[i].pose.x);
        ASSERT_EQ(a[i].pose.y, b[i].pose.y);
        ASSERT_EQ(a[i].pose.heading, b[i].pose.heading);
        ASSERT_EQ(a[i].bumped, b[i].bumped);
    }
    EXPECT_TRUE(a.size() != c.size() || a[5].pose.x != c[5].pose.x);
}

TEST(RandomWalk, ResumesExactlyFromItsState) {
    const World world = World::cross({.tilt_deg = 45});
    auto body = std::make_shared<const BodyCollider>(world.description(), R, 0.1);
    Rng rng(9, Stream::walk);
    const Pose start = RandomWalk::draw_start(world.description(), *body, rng);
    RandomWalk full(body, RobotParams{}, rng, start), part(body, RobotParams{}, rng, start);
    std::vector<ModelStep> a, b;
    while (auto s = full.next(1800)) a.push_back(*s);
    while (auto s = part.next(900)) b.push_back(*s);
    // Through the Agent interface's text state, as checkpoints save it.
    const std::string saved = part.save_state();
    RandomWalk resumed(body, RobotParams{}, Rng(0, Stream::walk), Pose{});
    resumed.restore_state(saved);
    while (auto s = resumed.next(1800)) b.push_back(*s);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i].pose.x, b[i].pose.x) << i;
        ASSERT_EQ(a[i].pose.heading, b[i].pose.heading) << i;
        ASSERT_EQ(a[i].t, b[i].t) << i;
    }
    EXPECT_THROW(resumed.restore_state("trajectory 3"), InputError);
}

TEST(BodyCollider, ExactContactDistances) {
    WorldDescription w;
    w.name = "post";
    w.mesh = box_mesh(Vec3(1.0, 1.0, 2.0));  // a 1 m post from z = -1 to 1, so 0 < z <= 0.1 is inside it
    w.walkable = Polygon2::rectangle(-5, -5, 5, 5);
    const BodyCollider body(w, R, 0.1);
    // Head-on into the face x = -0.5 from x = -2: contact when the center reaches -0.75.
    EXPECT_NEAR(body.free_distance(Vec2(-2, 0), Vec2(1, 0), 5.0), 1.25, 1e-12);
    // Grazing the corner (-0.5, 0.5) from y = 0.6: contact where |c - corner| = R.
    const double dy = 0.1;
    EXPECT_NEAR(body.free_distance(Vec2(-2, 0.5 + dy), Vec2(1, 0), 5.0), 1.5 - std::sqrt(R * R - dy * dy), 1e-12);
    // Passing clear of it, and the walkable boundary stopping the body.
    EXPECT_NEAR(body.free_distance(Vec2(-2, 0.8), Vec2(1, 0), 10.0), 7.0 - R, 1e-12);
    EXPECT_NEAR(body.clearance(Vec2(-2, 0)), 1.5 - R, 1e-12);
    EXPECT_TRUE(body.is_free(Vec2(-2, 0)));
    EXPECT_FALSE(body.is_free(Vec2(-0.6, 0)));
    // Touching and moving into the contact: blocked; moving away: free.
    EXPECT_EQ(body.free_distance(Vec2(-0.75 + 1e-12, 0), Vec2(1, 0), 1.0), 0.0);
    EXPECT_EQ(body.free_distance(Vec2(-0.75 + 1e-12, 0), Vec2(-1, 0), 1.0), 1.0);
}

namespace {
// A walkable square with a solid 2 x 2 x 1 m box in its middle.
WorldDescription box_world(StartRegion start = {}) {
    WorldDescription w;
    w.name = "box";
    w.mesh.append(box_mesh(Vec3(2, 2, 1)), Eigen::Isometry3d(Eigen::Translation3d(0, 0, 0.5)));
    w.mesh.add_quad(Vec3(-4, -4, 3), Vec3(4, -4, 3), Vec3(4, 4, 3), Vec3(-4, 4, 3));  // a ceiling, for rays
    w.walkable = Polygon2::rectangle(-4, -4, 4, 4);
    w.start = start;
    if (w.start.points.empty() && w.start.region.points.empty()) w.start.region = w.walkable;
    return w;
}
}  // namespace

TEST(RandomWalk, NeverStartsInsideASolidObstacle) {
    const World world(box_world());
    for (std::uint64_t seed = 0; seed < 120; ++seed) {
        const auto s = random_walk(world, 0.002, seed);
        ASSERT_FALSE(s.empty());
        // Outside the box's footprint grown by the body radius (the box spans |x|, |y| <= 1).
        EXPECT_GT(std::max(std::abs(s[0].pose.x), std::abs(s[0].pose.y)), 1.0 + R - 1e-6) << "seed " << seed;
    }
    const BodyCollider body(box_world(), R, 0.1);
    EXPECT_TRUE(body.is_free(Vec2(0, 0)));  // far from every wall, yet inside the box:
    EXPECT_FALSE(body.can_start_at(Vec2(0, 0)));
    EXPECT_TRUE(body.can_start_at(Vec2(3, 3)));
    const auto [inside, largest] = body.free_area(Vec2(0, 0));
    EXPECT_NEAR(inside, 1.5 * 1.5, 0.3);  // the body's center can roam |x|, |y| <= 0.75 in there
    EXPECT_NEAR(largest, 64 - 2.5 * 2.5 - (8 * 8 - 7.5 * 7.5), 1.5);
    // An explicit start point inside the box, or a start region that lies entirely inside it.
    try {
        World w(box_world(StartRegion{{Vec2(0, 0)}, {}}));
        random_walk(w, 0.01, 1);
        ADD_FAILURE();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("closed-off free area"), std::string::npos) << e.what();
    }
    EXPECT_THROW(random_walk(World(box_world(StartRegion{{}, Polygon2::rectangle(-0.5, -0.5, 0.5, 0.5)})), 0.01, 1),
                 InputError);
}

TEST(RandomWalk, AJammedRobotIsAnErrorNotAHang) {
    // A pocket barely wider than the body: every heading is blocked at once.
    WorldDescription w;
    w.name = "pocket";
    w.mesh.add_quad(Vec3(-1, -1, 2), Vec3(1, -1, 2), Vec3(1, 1, 2), Vec3(-1, 1, 2));
    w.walkable = Polygon2::rectangle(-0.2501, -0.2501, 0.2501, 0.2501);
    w.start.points = {Vec2(0, 0)};
    RobotParams fast;
    fast.turn_rate = 1e6;  // turns take no time: without the jam check this would never end
    EXPECT_THROW(random_walk(World(w), 1.0, 0, fast), InputError);
}

// The authors' robot (docs/reproduction.md#the-authors-configuration): turns last whole 96 ms
// control steps at 1.83 rad/s and overshoot their target by less than one step; a bump draws a
// uniform heading and then makes the Gaussian turn too; the start heading is fixed.
TEST(RandomWalk, AuthorsRobotTurnsInWholeControlSteps) {
    const World world = World::cross(CrossArenaParams::webots(30));
    const RobotParams p = RobotParams::authors();
    auto body = std::make_shared<const BodyCollider>(world.description(), p.radius, p.height);
    Rng rng(5, Stream::walk);
    const Pose start = RandomWalk::draw_start(world.description(), *body, rng);
    RandomWalk walk(body, p, rng, start);
    std::vector<TurnEvent> log;
    walk.log_turns(&log);
    std::vector<ModelStep> steps;
    while (auto s = walk.next(3 * 3600.0)) steps.push_back(*s);

    const double per_step = 1.83 * 0.096;
    std::size_t turns = 0, overshoots = 0, mismatched = 0;
    for (std::size_t i = 0; i + 1 < steps.size(); ++i) {
        const auto &a = steps[i], &b = steps[i + 1];
        if (a.bumped || b.bumped || a.pose.heading == b.pose.heading) continue;
        // A Gaussian turn between two full steps: k whole control steps, k · 1.83 · 0.096 rad.
        // (A turn that runs into a wall at once adds an unrecorded bump in between: rare.)
        const double k = (b.t - a.t - p.model_dt) / 0.096;
        if (std::abs(k - std::round(k)) > 1e-6 || std::round(k) < 1) {
            ++mismatched;
            continue;
        }
        const double turned = std::abs(wrap_pi(b.pose.heading - a.pose.heading));
        if (std::round(k) * per_step < pi - per_step) {
            EXPECT_NEAR(turned, std::round(k) * per_step, 1e-9) << i;
            ++turns;
        }
    }
    EXPECT_GT(turns, 500u);
    EXPECT_LT(mismatched, steps.size() / 500);
    // Each drawn Gaussian turn is overshot by [0, one step): the realized turns' overshoots, read off
    // the log (a Gaussian turn d realizes ceil(|d| / step) steps), are spread over the step.
    for (const auto& e : log)
        if (e.kind == TurnEvent::Kind::gaussian && std::abs(e.drawn) < pi - per_step) {
            const double over = std::ceil(std::abs(e.drawn) / per_step) * per_step - std::abs(e.drawn);
            ASSERT_GE(over, 0.0);
            ASSERT_LT(over, per_step);
            overshoots += over > per_step / 2;
        }
    EXPECT_GT(overshoots, 300u);
    // Every bump's uniform heading is followed by a Gaussian turn.
    std::size_t bumps = 0;
    for (std::size_t i = 0; i + 1 < log.size(); ++i)
        if (log[i].kind == TurnEvent::Kind::bump) {
            ++bumps;
            EXPECT_EQ(log[i + 1].kind, TurnEvent::Kind::gaussian) << i;
        }
    EXPECT_GT(bumps, 200u);
}

TEST(RandomWalk, FixedStartHeadingKeepsTheDrawnStartPoint) {
    const World world = World::cross();
    RobotParams fixed;
    fixed.fixed_start_heading = true;
    fixed.start_heading = 1.25;
    for (std::uint64_t seed = 0; seed < 8; ++seed) {
        auto a = RandomWalkSpec().make(&world, seed), b = RandomWalkSpec(fixed).make(&world, seed);
        const auto& wa = dynamic_cast<const RandomWalk&>(*a);
        const auto& wb = dynamic_cast<const RandomWalk&>(*b);
        EXPECT_EQ(wb.pose().heading, 1.25);
        EXPECT_EQ(wa.pose().x, wb.pose().x);
        EXPECT_EQ(wa.pose().y, wb.pose().y);
    }
}

// With a logging lag the walk is the same and each step is logged where the robot is `lag` seconds
// later. Oracle: the path rebuilt from the steps alone: between two steps the robot turns in place,
// then drives straight to the next step at 0.5 m/s (bump moves of < 1 mm that update nothing are
// the only thing it cannot see).
TEST(RandomWalk, LogLagLogsWhereTheRobotIsLater) {
    const World world = World::cross({.tilt_deg = 45});
    RobotParams lagged;
    lagged.log_lag = 0.192;
    const auto plain = random_walk(world, 1.0, 8), steps = random_walk(world, 1.0, 8, lagged);
    ASSERT_EQ(plain.size(), steps.size());
    const auto position_at = [&](double t, std::size_t from) {
        for (std::size_t j = from; j + 1 < steps.size(); ++j) {
            const auto &a = steps[j], &b = steps[j + 1];
            if (t > b.t) continue;
            const double d = std::hypot(b.pose.x - a.pose.x, b.pose.y - a.pose.y), t_go = b.t - d / 0.5;
            if (t <= t_go) return std::pair{a.pose.x, a.pose.y};
            const double f = (t - t_go) / (b.t - t_go);
            return std::pair{a.pose.x + f * (b.pose.x - a.pose.x), a.pose.y + f * (b.pose.y - a.pose.y)};
        }
        return std::pair{double(NAN), double(NAN)};
    };
    std::size_t exact = 0, checked = 0, moved = 0, still = 0;
    for (std::size_t i = 0; i + 2 < steps.size(); ++i) {
        ASSERT_EQ(steps[i].pose.x, plain[i].pose.x);
        ASSERT_EQ(steps[i].t, plain[i].t);
        ASSERT_TRUE(steps[i].logged_pose.has_value());
        const auto& logged = *steps[i].logged_pose;
        EXPECT_EQ(logged.heading, steps[i].pose.heading);  // only the position lags
        const auto [x, y] = position_at(steps[i].t + 0.192, i);
        const double err = std::hypot(logged.x - x, logged.y - y);
        ASSERT_LT(err, 2e-3) << i;
        exact += err < 1e-9;
        ++checked;
        const double shift = std::hypot(logged.x - steps[i].pose.x, logged.y - steps[i].pose.y);
        moved += std::abs(shift - 0.096) < 1e-9;
        still += shift == 0;
    }
    EXPECT_GT(exact, checked * 99 / 100);
    EXPECT_GT(moved, checked / 2);   // most steps are followed by straight driving: 0.192 s × 0.5 m/s
    EXPECT_GT(still, checked / 50);  // turns longer than the lag
    EXPECT_FALSE(plain[0].logged_pose.has_value());
}

TEST(BodyCollider, SpheresAreTheirDiscsInTheBodySlab) {
    // A ball of radius 0.25 centered 0.2 m above the body's top (H = 0.1): its slice through the
    // slab is a disc of radius √(0.25² − 0.2²) = 0.15. A ball 0.3 m above misses the slab.
    WorldDescription w;
    w.name = "balls";
    w.spheres.push_back(SphereSet{{Vec3(0, 0, 0.3), Vec3(0, 3, 0.4)}, 0.25});
    w.walkable = Polygon2::rectangle(-5, -5, 5, 5);
    const BodyCollider body(w, R, 0.1);
    EXPECT_NEAR(body.free_distance(Vec2(-2, 0), Vec2(1, 0), 5.0), 2.0 - (R + 0.15), 1e-12);
    EXPECT_NEAR(body.free_distance(Vec2(-2, 3), Vec2(1, 0), 5.0), 5.0, 1e-12);  // passes under the high ball
    EXPECT_NEAR(body.clearance(Vec2(1, 0)), 1.0 - 0.15 - R, 1e-12);

    // Against an independent oracle: the body (cylinder, 0 < z <= H) and a ball overlap iff some
    // height z in the slab has the ball's cross-section disc reaching the body's disc; checked on
    // a fine grid of z for random positions not within 1 mm of contact.
    std::uint64_t state = 99;
    auto uniform = [&] {
        state = state * 6364136223846793005ull + 1442695040888963407ull;
        return static_cast<double>(state >> 11) / 9007199254740992.0;
    };
    WorldDescription cloud;
    cloud.name = "cloud";
    cloud.spheres.push_back({});
    cloud.spheres[0].radius = 0.08;
    for (int i = 0; i < 60; ++i)
        cloud.spheres[0].centers.emplace_back(-2 + 4 * uniform(), -2 + 4 * uniform(), -0.1 + 0.35 * uniform());
    cloud.walkable = Polygon2::rectangle(-5, -5, 5, 5);
    const double H = 0.1;
    const BodyCollider cb(cloud, R, H);
    int overlaps = 0, checked = 0;
    for (int i = 0; i < 3000; ++i) {
        const Vec2 p(-2 + 4 * uniform(), -2 + 4 * uniform());
        double reach = INFINITY;  // min over z of (horizontal gap to the body) - (cross-section radius)
        for (const Vec3& c : cloud.spheres[0].centers) {
            if ((p - c.head<2>()).norm() > R + 0.1) {  // too far for any slice to reach
                reach = std::min(reach, (p - c.head<2>()).norm() - R - 0.08);
                continue;
            }
            for (int k = 1; k <= 2000; ++k) {
                const double z = H * k / 2000.0, dz = z - c.z();
                if (std::abs(dz) >= 0.08) continue;
                reach = std::min(reach, (p - c.head<2>()).norm() - R - std::sqrt(0.08 * 0.08 - dz * dz));
            }
        }
        if (std::abs(reach) < 1e-3) continue;
        ++checked;
        overlaps += reach < 0;
        ASSERT_EQ(cb.clearance(p) < 0, reach < 0) << i;
    }
    EXPECT_GT(overlaps, 50);
    EXPECT_GT(checked, 2500);
}

// Why a start failed (navigation/failure_class.hpp): each class built on purpose from a hand-made path, bumps and
// reward map whose answer follows from the rules' words (distances, counts and the map's hills are set by hand), and
// the order in which the rules are tried.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/navigation/failure_class.hpp"

using namespace bvc3d;

namespace {

// A lattice of `cell` m over [-10, 10]² and values f(point) on it.
struct Map {
    std::vector<Vec2> points;
    std::vector<double> values;
};
template <class F>
Map lattice(F f, double cell = 0.5) {
    Map m;
    for (double y = -10 + cell / 2; y < 10; y += cell)
        for (double x = -10 + cell / 2; x < 10; x += cell)
            m.points.emplace_back(x, y), m.values.push_back(f(Vec2(x, y)));
    return m;
}

// A hill of height h and width w at c.
double hill(const Vec2& p, const Vec2& c, double h, double w) { return h * std::exp(-(p - c).squaredNorm() / (w * w)); }

// A straight walk from a to b in `n` equal moves.
std::vector<Vec3> line(const Vec2& a, const Vec2& b, int n) {
    std::vector<Vec3> out;
    for (int k = 0; k <= n; ++k) {
        const Vec2 p = a + (b - a) * (double(k) / n);
        out.emplace_back(p.x(), p.y(), 0.0);
    }
    return out;
}

struct Case {
    std::vector<Vec3> path;
    std::vector<char> bumped;
    Map map;
    FailedStart start(StartEnd end, const Vec2& goal, double at_quarter, double at_end) const {
        FailedStart s;
        s.end = end;
        s.path = path;
        s.bumped = bumped;
        s.goal = goal;
        s.distance_at_last_quarter = at_quarter;
        s.distance_at_end = at_end;
        s.map_points = map.points;
        s.map_values = map.values;
        s.map_cell = 0.5;
        return s;
    }
};

const Vec2 goal(7, 7);
// The goal's own hill: climbing from anywhere leads to it.
double toward_goal(const Vec2& p) { return hill(p, goal, 1.0, 12.0); }

}  // namespace

TEST(FailureClass, NamesAreOnePerClassAsStartsCsvWritesThem) {
    EXPECT_EQ(failure_class_names().size(), 7u);
    EXPECT_EQ(to_string(FailureClass::none), "");
    EXPECT_EQ(to_string(FailureClass::closing_in), "closing-in");
    EXPECT_EQ(to_string(FailureClass::wrong_basin), "wrong-basin");
}

TEST(FailureClass, TailStartIsWhereTheLastFractionByLengthBegins) {
    // Ten moves of 1 m: the last quarter (2.5 m) begins 3 moves from the end, the last half (5 m) at the middle.
    const auto path = line({0, 0}, {10, 0}, 10);
    EXPECT_EQ(tail_start(path, 0.25), 7u);
    EXPECT_EQ(tail_start(path, 0.5), 5u);
    EXPECT_EQ(tail_start(path, 1.0), 0u);
    EXPECT_EQ(tail_start(std::vector<Vec3>{Vec3::Zero()}, 0.25), 0u);
}

TEST(FailureClass, AReachedStartHasNoClass) {
    Case c{line({0, 0}, {6.5, 6.5}, 50), std::vector<char>(50, 0), lattice(toward_goal)};
    EXPECT_EQ(classify_failure(c.start(StartEnd::reached, goal, 5, 0.7)), FailureClass::none);
}

TEST(FailureClass, BlockedWhenWedgedOrPushingAgainstAWall) {
    // Wedged: blocked whatever else holds (here a path that would otherwise be closing in).
    Case wedged{line({0, 0}, {4, 4}, 30), std::vector<char>(30, 0), lattice(toward_goal)};
    EXPECT_EQ(classify_failure(wedged.start(StartEnd::wedged, goal, 6, 4)), FailureClass::blocked);
    // Walked 5 m, then 20 moves jittering 0.1 m back and forth against a wall, every other one touching it.
    Case pushing{line({0, 0}, {5, 0}, 20), std::vector<char>(20, 0), lattice(toward_goal)};
    for (int k = 0; k < 20; ++k) {
        pushing.path.emplace_back(5.0 + 0.1 * (k % 2), 0.0, 0.0);
        pushing.bumped.push_back(k % 2 == 0);
    }
    EXPECT_EQ(classify_failure(pushing.start(StartEnd::path_cap, goal, 7, 7)), FailureClass::blocked);
    // The same jitter touching nothing (fewer than half the moves bumped) is not blocked.
    std::fill(pushing.bumped.begin() + 20, pushing.bumped.end(), 0);
    pushing.bumped[25] = pushing.bumped[27] = 1;
    EXPECT_NE(classify_failure(pushing.start(StartEnd::path_cap, goal, 7, 7)), FailureClass::blocked);
}

TEST(FailureClass, ClosingInWhenACapEndsItWhileItsDistanceStillFalls) {
    // A straight approach cut short: 4 m nearer at the end than where its last quarter began.
    Case c{line({-7, -7}, {3, 3}, 100), std::vector<char>(100, 0), lattice(toward_goal)};
    EXPECT_EQ(classify_failure(c.start(StartEnd::path_cap, goal, 9.6, 5.7)), FailureClass::closing_in);
    EXPECT_EQ(classify_failure(c.start(StartEnd::time_cap, goal, 9.6, 5.7)), FailureClass::closing_in);
    // Less than 1 m gained over the last quarter is not closing in (the map leads to the goal, no loop: wander).
    EXPECT_EQ(classify_failure(c.start(StartEnd::path_cap, goal, 6.5, 5.7)), FailureClass::wander);
}

TEST(FailureClass, PlateauWhenTheMapIsFlatWhereItWalked) {
    // The goal's hill is narrow (width 2 m); the agent wanders in the far corner where the map is < 1 % of its top.
    Map narrow = lattice([](const Vec2& p) { return hill(p, goal, 1.0, 2.0); });
    std::vector<Vec3> path = line({-8, -8}, {-8, -2}, 30);
    const auto back = line({-8, -2}, {-2, -8}, 30);
    path.insert(path.end(), back.begin() + 1, back.end());
    Case c{path, std::vector<char>(60, 0), narrow};
    EXPECT_EQ(classify_failure(c.start(StartEnd::path_cap, goal, 13, 14)), FailureClass::plateau);
    // With the goal's wide hill over the same walk it is not a plateau (and climbing leads to the goal: wander).
    c.map = lattice(toward_goal);
    EXPECT_EQ(classify_failure(c.start(StartEnd::path_cap, goal, 13, 14)), FailureClass::wander);
}

TEST(FailureClass, WrongBasinWhenClimbingFromItsEndLeadsToAnotherHill) {
    // A second, lower hill at (-5, -5) beside the goal's: the agent ends on its slope and climbing ends on its top.
    Map two = lattice([](const Vec2& p) { return toward_goal(p) * 0.5 + hill(p, {-5, -5}, 0.6, 2.0); });
    Case c{line({0, -8}, {-4, -4}, 40), std::vector<char>(40, 0), two};
    EXPECT_EQ(classify_failure(c.start(StartEnd::path_cap, goal, 15, 15.5)), FailureClass::wrong_basin);
    // The same walk over the goal's hill alone: climbing reaches the goal, so not a wrong basin.
    c.map = lattice(toward_goal);
    EXPECT_EQ(classify_failure(c.start(StartEnd::path_cap, goal, 15, 15.5)), FailureClass::wander);
}

TEST(FailureClass, LoopWhenItCirclesInItsLastQuarter) {
    // 10 m straight, then three circles of radius 1 m (≈ 18.8 m): the last quarter returns to places it left ≥ 3 m of
    // path before. Bumps none, the map leads to the goal, the distance does not fall.
    std::vector<Vec3> path = line({-8, -8}, {-2, 0}, 40);
    for (int k = 1; k <= 120; ++k) {
        const double a = 2 * pi * k / 40;
        path.emplace_back(-3 + std::cos(a), std::sin(a), 0.0);
    }
    Case c{path, std::vector<char>(path.size() - 1, 0), lattice(toward_goal)};
    EXPECT_EQ(classify_failure(c.start(StartEnd::path_cap, goal, 11.4, 11.6)), FailureClass::loop);
    // In flight there is no map: the rules that need one are skipped and the loop still names it.
    c.map = {};
    EXPECT_EQ(classify_failure(c.start(StartEnd::path_cap, goal, 11.4, 11.6)), FailureClass::loop);
}

TEST(FailureClass, TheRulesAreTriedInOrder) {
    // A path that is at once closing in and circling: closing in names it (tried first).
    std::vector<Vec3> path = line({-8, -8}, {-2, 0}, 40);
    for (int k = 1; k <= 120; ++k) {
        const double a = 2 * pi * k / 40;
        path.emplace_back(-3 + std::cos(a), std::sin(a), 0.0);
    }
    Case c{path, std::vector<char>(path.size() - 1, 0), lattice(toward_goal)};
    EXPECT_EQ(classify_failure(c.start(StartEnd::path_cap, goal, 13, 11.6)), FailureClass::closing_in);
    // Wedged while circling: blocked.
    EXPECT_EQ(classify_failure(c.start(StartEnd::wedged, goal, 11.4, 11.6)), FailureClass::blocked);
}

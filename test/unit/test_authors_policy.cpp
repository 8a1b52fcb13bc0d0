// The authors' controller (policy `authors`, navigation/authors_policy.hpp) run start by start on a model whose
// choice is known: place cells that say which way the robot faces, and an adjacency along which the only rewarded
// direction is 90° to the left. So it turns left at every decision and drives a square: loops are counted and, with
// exact headings, cost the scales nothing (the authors' bookkeeping); turns that cannot be completed feed the loop
// penalty; a box too small for any safe direction makes every decision an exploration block; a body that never
// moves drives every ρ to the floor and forces exploration. The draws come from the start's stream: the same seed,
// the same path. (The pieces of a decision against numpy: test/python/test_authors_policy.py.)
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "../support/temp_dir.hpp"

#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/navigation/authors_policy.hpp"

using namespace bvc3d;

namespace {

constexpr int n_cells = 8;

// Place cell i is on when the robot faces 45°·i (to the nearest); no learning, an adjacency of its own.
class FacingSenses : public NavigationSenses {
public:
    explicit FacingSenses(const HdAdjacency& adj) : adj_(adj), rates_(1, std::vector<double>(n_cells, 0.0)) {}
    const std::vector<std::vector<double>>& step(const Pose& pose, bool, double) override {
        ++steps;
        std::fill(rates_[0].begin(), rates_[0].end(), 0.0);
        const int i = static_cast<int>(std::lround(pose.heading / (pi / 4)));
        rates_[0][std::size_t((i % n_cells + n_cells) % n_cells)] = 1.0;
        return rates_;
    }
    const std::vector<std::vector<double>>& rates() const override { return rates_; }
    void reset() override { ++resets; }
    void reload() override { ++reloads; }
    void set_learning(bool) override {}
    const HdAdjacency& adjacency(std::size_t) const override { return adj_; }
    int steps = 0, resets = 0, reloads = 0;

private:
    const HdAdjacency& adj_;
    std::vector<std::vector<double>> rates_;
};

// Along direction i + 2 (90° left of facing i), cell i leads to cell i + 1: the only rollout that is rewarded.
HdAdjacency turn_left() {
    HdAdjacency adj(n_cells);
    std::vector<float> w(std::size_t(8) * n_cells * n_cells, 0.0f);
    for (int i = 0; i < n_cells; ++i) {
        const int k = (i + 2) % 8, to = (i + 1) % n_cells;
        w[(std::size_t(k) * n_cells + std::size_t(to)) * n_cells + std::size_t(i)] = 2.0f;
    }
    adj.set_weights(w);
    return adj;
}

World world_of(const std::filesystem::path& dir, double half) {
    const auto file = dir / "box.yaml";
    const double h = half, t = h + 0.1;
    std::ofstream(file) << "name: box\nobjects:\n"
                        << "  - box: {center: [0, 0, -0.05], size: [" << 2 * h << ", " << 2 * h << ", 0.1]}\n"
                        << "  - box: {center: [" << -t << ", 0, 1.25], size: [0.2, " << 2 * t + 0.2 << ", 2.5]}\n"
                        << "  - box: {center: [" << t << ", 0, 1.25], size: [0.2, " << 2 * t + 0.2 << ", 2.5]}\n"
                        << "  - box: {center: [0, " << -t << ", 1.25], size: [" << 2 * t + 0.2 << ", 0.2, 2.5]}\n"
                        << "  - box: {center: [0, " << t << ", 1.25], size: [" << 2 * t + 0.2 << ", 0.2, 2.5]}\n"
                        << "walkable: {rect: [" << -h << ", " << -h << ", " << h << ", " << h << "]}\n";
    return World(config::load_world_file(file.string()));
}

// Everything a controller is made from, for one world.
struct Rig {
    World world;
    NavigationSpaceSpec spec;
    std::unique_ptr<NavigationSpace> space;
    HdAdjacency adj = turn_left();
    FacingSenses senses{adj};
    std::vector<ScaleMemory> memory;
    RewardParams reward;
    LidarSpec sensor = LidarSpec::horizontal();
    Rig(World w, double goal) : world(std::move(w)) {
        spec.goals = {{goal, goal}};
        space = make_navigation_space(world.description(), spec);
        memory.push_back(scale_memory(adj, AdjacencyParams{}, RewardParams{}));
        memory.back().rewards = {std::vector<double>(n_cells, 1.0)};
    }
    PolicyContext context() { return {world, *space, spec, senses, memory, reward, sensor}; }
    AuthorsController controller(const AuthorsParams& p, std::unique_ptr<AuthorsBody> body = nullptr) {
        if (!body) body = floor_body(world, spec.robot, sensor, p.contact);
        return AuthorsController(context(), p, std::move(body));
    }
};

StartTask far_goal(double max_path) { return {0, Vec3(50, 50, 0), 1.0, max_path, 3600}; }

AuthorsParams no_learning() {
    AuthorsParams p;
    p.learn = false;
    return p;
}

// A body that cannot complete turns larger than `max_turn`, or never moves; otherwise the floor's.
class StubbornBody : public AuthorsBody {
public:
    StubbornBody(std::unique_ptr<AuthorsBody> inner, double max_turn, bool moves)
        : inner_(std::move(inner)), max_turn_(max_turn), moves_(moves) {}
    bool turn(Pose& pose, double heading) override {
        if (std::abs(wrap_pi(heading - pose.heading)) > max_turn_) return false;
        return inner_->turn(pose, heading);
    }
    double forward(Pose& pose, double step) override { return moves_ ? inner_->forward(pose, step) : 0.0; }
    std::vector<double> scan(const Pose& pose, int beams) const override { return inner_->scan(pose, beams); }

private:
    std::unique_ptr<AuthorsBody> inner_;
    double max_turn_;
    bool moves_;
};

}  // namespace

TEST(AuthorsPolicy, TurnsLeftEveryDecisionDrivesASquareAndCountsItsLoopsWithoutPenalty) {
    test::TempDir dir;
    Rig rig(world_of(dir.path(), 10.0), 8.0);
    const AuthorsParams p = no_learning();
    auto controller = rig.controller(p);
    Rng rng(7, Stream::walk);
    const StartRun run = controller.run(Pose::on_floor(0, 0, 0), far_goal(40.0), rng);
    const AuthorsStats& s = controller.stats();
    EXPECT_EQ(run.end, StartEnd::path_cap);
    EXPECT_EQ(rig.senses.resets, 1);
    EXPECT_EQ(rig.senses.reloads, 0);
    // 10 settling updates, then per decision one update and a block of 10 (an update and a step each).
    EXPECT_EQ(s.unsafe + s.forced + s.failed_turns, 0);
    EXPECT_EQ(std::size_t(rig.senses.steps), 10 + 11 * std::size_t(s.decisions));
    EXPECT_EQ(run.path.size(), 1 + 10 * std::size_t(s.decisions));
    // Each block turns left by about 90°–135° (the rewarded direction's rollouts turn left again with the turn's
    // softmax; the cell says the facing to the nearest 45°):
    // it circles near its start, seeing a full turn every 3–4 decisions; with exact headings the loop's share of each
    // scale is 0 (the turn lands in the block's steps, not at the decision), so no penalty (as the authors' code).
    for (std::size_t d = 1; d < std::size_t(s.decisions); ++d) {
        const Vec3 a = run.path[(d - 1) * 10], b = run.path[d * 10], c = run.path[(d + 1) * 10 - 1];
        const double turn = wrap_pi(std::atan2((c - b).y(), (c - b).x()) - std::atan2((b - a).y(), (b - a).x()));
        EXPECT_GT(turn, deg_to_rad(60)) << d;
        EXPECT_LT(turn, deg_to_rad(160)) << d;
    }
    for (const Vec3& q : run.path) EXPECT_LT(q.head<2>().norm(), 3.0);
    EXPECT_GE(s.full_turns, s.decisions / 4 - 1);
    EXPECT_GE(s.full_turns, 5);
    EXPECT_EQ(s.loop_penalties, 0);
    // The same seed, the same path; each decision's 160 uniforms decide the rollouts' turns.
    auto again = rig.controller(p);
    Rng same(7, Stream::walk);
    EXPECT_EQ(again.run(Pose::on_floor(0, 0, 0), far_goal(40.0), same).path, run.path);
}

TEST(AuthorsPolicy, TurnsThatCannotBeCompletedTurnRandomlyAndFeedTheLoopPenalty) {
    test::TempDir dir;
    Rig rig(world_of(dir.path(), 10.0), 8.0);
    AuthorsParams p = no_learning();
    // The 90°–135° turns the choice asks for cannot be completed; the failed turn's own (within ±45°) can.
    auto controller =
        rig.controller(p, std::make_unique<StubbornBody>(floor_body(rig.world, rig.spec.robot, rig.sensor, p.contact),
                                                         deg_to_rad(50), true));
    Rng rng(3, Stream::walk);
    const StartRun run = controller.run(Pose::on_floor(0, 0, 0), far_goal(12.0), rng);
    const AuthorsStats& s = controller.stats();
    EXPECT_EQ(run.end, StartEnd::path_cap);
    EXPECT_EQ(s.failed_turns, s.decisions);
    EXPECT_GT(s.decisions, 20);
    EXPECT_EQ(s.forced + s.unsafe, 0);
    // Each failed turn: 3 steps (an update and a step each) after the decision's update.
    EXPECT_EQ(std::size_t(rig.senses.steps), 10 + 4 * std::size_t(s.decisions));
    EXPECT_EQ(run.path.size(), 1 + 3 * std::size_t(s.decisions));
    // The random turns happen after the block's steps were counted, so the next decision sees them: they are the
    // scales' share of the loop, and a full turn of them costs reliability (with exact headings, nothing else does).
    EXPECT_GE(s.full_turns, 1);
    EXPECT_GE(s.loop_penalties, 1);
}

TEST(AuthorsPolicy, ABoxWithNoSafeDirectionMakesEveryDecisionAnExplorationBlock) {
    test::TempDir dir;
    // 1.2 m across: wherever the body (radius 0.25 m) fits, a wall within 1 m in every 45° sector.
    Rig rig(world_of(dir.path(), 0.6), 0.0);
    auto controller = rig.controller(no_learning());
    Rng rng(5, Stream::walk);
    StartTask task = far_goal(1e9);
    task.max_s = 300;
    const StartRun run = controller.run(Pose::on_floor(0, 0, 0.3), task, rng);
    const AuthorsStats& s = controller.stats();
    EXPECT_EQ(run.end, StartEnd::time_cap);
    EXPECT_EQ(s.decisions, 0);
    EXPECT_GT(s.unsafe, 10);
    // It bumps the walls and turns away (an exploration block's contact turn), and never leaves the box.
    int bumps = 0;
    for (char b : run.bumped) bumps += b;
    EXPECT_GT(bumps, 0);
    for (const Vec3& q : run.path) EXPECT_LE(q.head<2>().lpNorm<Eigen::Infinity>(), 0.6 - 0.25 + 1e-9);
}

TEST(AuthorsPolicy, ABodyThatNeverMovesDrivesReliabilityDownAndForcesExploration) {
    test::TempDir dir;
    Rig rig(world_of(dir.path(), 10.0), 8.0);
    AuthorsParams p = no_learning();
    auto controller = rig.controller(
        p, std::make_unique<StubbornBody>(floor_body(rig.world, rig.spec.robot, rig.sensor, p.contact), 10.0, false));
    Rng rng(9, Stream::walk);
    StartTask task = far_goal(1e9);
    task.max_s = 600;
    controller.run(Pose::on_floor(0, 0, 0), task, rng);
    const AuthorsStats& s = controller.stats();
    // ρ: 1 → 0.6 → 0.36 → 0.216 → 0.1296 < 0.15 after four blocks ending in contact: ten forced exploration blocks
    // (×1.03 each: 0.174); a block in contact, 0.1045: ten more (0.1405, still below 0.15, so the trigger stays
    // spent); then ρ sits at the floor 0.1 and the ten blocks that would follow never come (0.1·1.03¹⁰ = 0.134).
    EXPECT_EQ(s.forced, 20);
    EXPECT_GE(s.decisions, 5);
}

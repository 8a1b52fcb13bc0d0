// Adaptive elevations (docs/adaptive.md): the chooser's criterion against the trial pipeline run
// on the same walk by hand, the shelf world, determinism and bad input.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "bvc3d/agent/flying_walk.hpp"
#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/elevation_chooser.hpp"
#include "bvc3d/experiment/pipeline.hpp"

using namespace bvc3d;

namespace {

const std::string shelf_world = std::string(BVC3D_SOURCE_DIR) + "/configs/worlds/twin-rooms-shelf.yaml";

ModelSpec spherical_base() { return model_preset("3d-0.2"); }

// The oracle: the walk twice as a trajectory with a long pause between the passes (the chooser
// uses one step's gap), learning through the first pass, analyzed by the trial pipeline, each
// elevation set alone in its own trial.
double msai_by_trial(const World& world, const std::vector<ModelStep>& walk, const std::vector<double>& elevations,
                     std::uint64_t seed, const ModelSpec& base = spherical_base(), int dims = 2) {
    std::vector<ModelStep> steps;
    const double t0 = walk.front().t, last = walk.back().t - t0;
    for (int pass = 0; pass < 2; ++pass)
        for (ModelStep s : walk) {
            s.t = s.t - t0 + pass * (last + 1000.0);
            steps.push_back(s);
        }
    TrialConfig t;
    t.model = base;
    t.model.bvc.elevations = elevations;
    t.model.bvc.n_per_axis = 960 / (8 * static_cast<int>(elevations.size()));
    t.agent = std::make_shared<TrajectorySpec>(steps, "oracle", dims);
    t.analysis = analysis::AnalysisParams::defaults(dims);
    t.protocol.explore_hours = (last - 0.01) / 3600.0;  // ends between the first pass's last two steps
    t.protocol.sample_hours = 1.0;
    t.seed = seed;
    const GroupResult r = run_trial_group(world, {t});
    EXPECT_EQ(r.stats.explore_steps, static_cast<std::int64_t>(walk.size()));
    EXPECT_EQ(r.stats.sample_steps, static_cast<std::int64_t>(walk.size()));
    return analyze(t, world.description(), r, 0).metrics.aliasing.msai;
}

}  // namespace

TEST(Adaptive, CriterionIsTheTrialPipelinesMsaiOnTheWalkTwice) {
    const World world(config::resolve_world("cross", 45.0));
    const auto walk = exploration_walk(world, RandomWalkSpec{}, 3, 6.0, 2.0);
    const std::vector<std::vector<double>> sets{{0.0, 0.2}, {0.1}, {0.0, 0.1, 0.3}};
    // Two threads: each runs its own group of sets on the shared walk.
    const auto scores = score_elevation_sets(world, spherical_base(), walk, sets, 960, 3, {}, 2);
    ASSERT_EQ(scores.size(), sets.size());
    for (std::size_t i = 0; i < sets.size(); ++i) {
        EXPECT_EQ(scores[i].elevations, sets[i]);
        EXPECT_EQ(scores[i].n_per_axis, 960 / (8 * static_cast<int>(sets[i].size())));
        ASSERT_TRUE(std::isfinite(scores[i].msai));
        EXPECT_DOUBLE_EQ(scores[i].msai, msai_by_trial(world, walk.steps, sets[i], 3)) << "set " << i;
    }
}

TEST(Adaptive, FlyingCriterionIsThe3dTrialPipelinesMsaiOnTheFlightTwice) {
    // A flying agent explores the flight room; candidates look down as well as up, and each is
    // scored on the flight volume's voxels (3-D analysis, DBSCAN min_samples 10) as its trials are.
    const World world(config::resolve_world("flight-room"));
    const FlightSpec agent;
    const auto defaults = chooser_defaults(agent);
    EXPECT_STREQ(defaults.sensor, "spherical-full");
    const ModelSpec base = model_preset(defaults.model);
    const auto walk = exploration_walk(world, agent, 4, 4.0, 2.0);
    ASSERT_EQ(walk.dims, 3);
    double z_lo = 1e9, z_hi = -1e9;
    for (const auto& s : walk.steps) z_lo = std::min(z_lo, s.pose.z), z_hi = std::max(z_hi, s.pose.z);
    EXPECT_GT(z_hi - z_lo, 0.5);  // it flies
    const std::vector<std::vector<double>> sets{{-0.2, 0.2}, {0.0}};
    const auto analysis = analysis::AnalysisParams::defaults(3);
    const auto scores = score_elevation_sets(world, base, walk, sets, 960, 4, analysis, 2);
    for (std::size_t i = 0; i < sets.size(); ++i) {
        ASSERT_TRUE(std::isfinite(scores[i].msai));
        EXPECT_DOUBLE_EQ(scores[i].msai, msai_by_trial(world, walk.steps, sets[i], 4, base, 3)) << "set " << i;
    }
    // The same walk analyzed in the plane gives another criterion: the voxels are what is scored.
    const auto flat = score_elevation_sets(world, base, ExplorationWalk{walk.steps, 2}, {sets[0]}, 960, 4, {}, 1);
    EXPECT_NE(flat[0].msai, scores[0].msai);
}

TEST(Adaptive, ChoosesALayerThatSeesTheShelf) {
    // Level layers see two alike rooms; only a layer looking up at 0.6 rad sees the shelf that
    // tells them apart (from 1.6–2.2 m away; a level layer at 0.18 m passes under it).
    const World world(config::resolve_world(shelf_world));
    ChooserParams p;
    p.elevation_min = 0.0;
    p.elevation_max = 0.6;
    p.elevation_step = 0.6;
    p.max_layers = 2;
    p.explore_minutes = 30;
    p.seed = 5;
    p.jobs = 2;
    const auto c = choose_elevations(world, spherical_base(), RandomWalkSpec{}, p);
    const auto& e = c.chosen.elevations;
    EXPECT_NE(std::find(e.begin(), e.end(), 0.6), e.end()) << "chose " << elevations_text(e);
    EXPECT_EQ(c.model.bvc.elevations, e);
    EXPECT_EQ(c.model.bvc.n_cells(), 960);
}

TEST(Adaptive, TheShelfChangesTheCriterionOnlyOfLayersThatSeeIt) {
    // The same world without its shelf: the walk is the same (the shelf is above the robot), the
    // level layer's criterion is unchanged to the bit, the upward layer's is not.
    const World with_shelf(config::load_world_file(shelf_world));
    std::ifstream in(shelf_world);
    std::string text, line;
    while (std::getline(in, line))
        if (line.find("the shelf") == std::string::npos) text += line + "\n";
    const auto tmp = std::filesystem::temp_directory_path() / ("bvc3d-noshelf-" + std::to_string(::getpid()) + ".yaml");
    std::ofstream(tmp) << text;
    const World no_shelf(config::load_world_file(tmp.string()));
    std::filesystem::remove(tmp);
    const auto walk = exploration_walk(with_shelf, RandomWalkSpec{}, 5, 10.0, 2.0);
    const auto walk_bare = exploration_walk(no_shelf, RandomWalkSpec{}, 5, 10.0, 2.0);
    ASSERT_EQ(walk.steps.size(), walk_bare.steps.size());
    EXPECT_EQ(walk.steps.back().pose.x, walk_bare.steps.back().pose.x);
    const std::vector<std::vector<double>> sets{{0.0}, {0.6}};
    const auto a = score_elevation_sets(with_shelf, spherical_base(), walk, sets, 960, 5, {}, 2);
    const auto b = score_elevation_sets(no_shelf, spherical_base(), walk, sets, 960, 5, {}, 2);
    EXPECT_EQ(a[0].msai, b[0].msai);
    EXPECT_NE(a[1].msai, b[1].msai);
}

TEST(Adaptive, SameSeedSameChoiceWhateverTheThreads) {
    const World world(config::resolve_world("cross", 60.0));
    ChooserParams p;
    p.elevation_max = 0.3;
    p.elevation_step = 0.15;
    p.max_layers = 2;
    p.explore_minutes = 5;
    p.seed = 11;
    p.jobs = 1;
    const auto a = choose_elevations(world, spherical_base(), RandomWalkSpec{}, p);
    p.jobs = 2;
    const auto b = choose_elevations(world, spherical_base(), RandomWalkSpec{}, p);
    ASSERT_EQ(a.candidates.size(), b.candidates.size());
    for (std::size_t i = 0; i < a.candidates.size(); ++i) {
        EXPECT_EQ(a.candidates[i].elevations, b.candidates[i].elevations);
        EXPECT_EQ(a.candidates[i].msai, b.candidates[i].msai);  // bit-identical
    }
    EXPECT_EQ(a.chosen.elevations, b.chosen.elevations);
    // Greedy: round 1 holds each candidate alone, round 2 the round-1 winner plus each other one.
    ASSERT_GE(a.candidates.size(), 3u);
    EXPECT_EQ(a.candidates[0].elevations, std::vector<double>{0.0});
    EXPECT_EQ(a.candidates[1].elevations, std::vector<double>{0.15});
    EXPECT_EQ(a.candidates[2].elevations, std::vector<double>{0.3});
}

TEST(Adaptive, BadInputIsRefusedClearly) {
    const World world(config::resolve_world("cross", 30.0));
    const auto refused = [&](ChooserParams p, const std::string& words) {
        try {
            choose_elevations(world, spherical_base(), RandomWalkSpec{}, p);
            ADD_FAILURE() << "accepted; expected: " << words;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    };
    ChooserParams p;
    p.budget = 40;  // 4 layers × 8 directions need 64 cells for 2 distances each
    refused(p, "too small for 4 layers");
    p = {};
    p.elevation_min = 0.3;
    p.elevation_max = 0.1;
    refused(p, "empty candidate range");
    p = {};
    p.explore_minutes = 0.05;  // 3 s: a few steps, all within 2 m
    refused(p, "explore longer");
    p = {};
    p.min_layers = 3;
    p.max_layers = 2;
    refused(p, "exceeds max_layers");
    p = {};
    p.elevation_step = 0;
    refused(p, "elevation_step");
}

// Trials (docs/model-reference.md#trial-protocol): shared walks, protocols, checkpoints and trial files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "bvc3d/analysis/metrics.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/experiment.hpp"
#include "bvc3d/experiment/pipeline.hpp"
#include "bvc3d/experiment/trial_runner.hpp"
#include "bvc3d/recorder/trial_file.hpp"

using namespace bvc3d;
namespace fs = std::filesystem;

namespace {

TrialConfig trial(const std::string& model, double tilt = 45, double hours = 0.05, std::uint64_t seed = 1) {
    TrialConfig t;
    t.world = WorldSpec{"cross", tilt, "+x+y"};
    t.model = model_preset(model);
    t.seed = seed;
    t.protocol.explore_hours = t.protocol.sample_hours = hours;
    return t;
}

fs::path temp_dir(const std::string& name) {
    const auto d = fs::temp_directory_path() / ("bvc3d-exp-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

std::string bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST(TrialGroup, SharedWalkGivesEachModelItsSoloResult) {
    const std::vector<TrialConfig> group{trial("2d"), trial("3d-0.2"), trial("3d-3l"), trial("2d-8beam")};
    const GroupResult together = run_trial_group(group);
    for (std::size_t i = 0; i < group.size(); ++i) {
        const GroupResult alone = run_trial_group({group[i]});
        ASSERT_EQ(alone.t, together.t);
        ASSERT_EQ(alone.x, together.x);
        EXPECT_EQ(alone.models[0].rates, together.models[i].rates) << group[i].model.name;
        EXPECT_EQ(alone.models[0].weights, together.models[i].weights) << group[i].model.name;
    }
    EXPECT_THROW(run_trial_group({trial("2d", 45), trial("3d-0.2", 30)}), InputError);
}

TEST(TrialGroup, ProtocolsRecordWhatTheySay) {
    TrialConfig t = trial("3d-0.1", 30, 0.1);
    t.protocol.record_bvc = true;
    const GroupResult r = run_trial_group({t});
    const std::size_t n = r.t.size();
    EXPECT_EQ(static_cast<std::int64_t>(n), r.stats.sample_steps);
    EXPECT_GT(r.stats.explore_steps, 800);
    EXPECT_GE(r.t.front(), 0.1 * 3600);  // nothing recorded while exploring
    EXPECT_NEAR(r.stats.end_time, 0.2 * 3600, 1.0);
    EXPECT_EQ(r.models[0].rates.size(), n * 250);
    EXPECT_EQ(r.models[0].bvc.size(), n * 960);
    EXPECT_EQ(r.models[0].weights.size(), 250u * 960u);
    EXPECT_EQ(r.stats.full_scan_fallbacks, 0);
    // Learning is off while sampling: weights after the trial equal those of exploration alone.
    TrialConfig explore_only = t;
    explore_only.protocol.kind = Protocol::Kind::online;
    explore_only.protocol.sample_hours = 0.1;
    const GroupResult online = run_trial_group({explore_only});
    EXPECT_LT(online.t.front(), 1.0);  // online: recorded from the first step
    EXPECT_EQ(online.models[0].weights, r.models[0].weights);
}

TEST(TrialGroup, InterruptedAndResumedFromCheckpointIsIdentical) {
    const auto dir = temp_dir("ckpt");
    const std::vector<TrialConfig> group{trial("2d", 60, 0.1), trial("3d-3l", 60, 0.1)};
    const GroupResult straight = run_trial_group(group);

    std::atomic<bool> stop{false};
    RunControl control;
    control.stop = &stop;
    control.checkpoint = dir / "group.h5";
    control.checkpoint_minutes = 3;
    control.progress = [&](double t, std::int64_t) {
        if (t > 0.13 * 3600) stop = true;  // interrupt during the sampling phase
    };
    EXPECT_THROW(run_trial_group(group, control), Interrupted);
    ASSERT_TRUE(fs::exists(control.checkpoint));
    stop = false;
    control.progress = nullptr;
    const GroupResult resumed = run_trial_group(group, control);
    EXPECT_EQ(resumed.t, straight.t);
    EXPECT_EQ(resumed.heading, straight.heading);
    for (std::size_t i = 0; i < group.size(); ++i) {
        EXPECT_EQ(resumed.models[i].rates, straight.models[i].rates);
        EXPECT_EQ(resumed.models[i].weights, straight.models[i].weights);
    }
    EXPECT_EQ(resumed.stats.bumps, straight.stats.bumps);
    // A checkpoint of another configuration is ignored, not resumed.
    const GroupResult other = run_trial_group({trial("2d", 60, 0.1, 2)}, control);
    EXPECT_NE(other.x, straight.x);
    fs::remove_all(dir);
}

TEST(TrialFiles, SameConfigurationGivesAByteIdenticalFile) {
    const auto dir = temp_dir("files");
    const TrialConfig t = trial("3d-0.2", 45, 0.05);
    ExperimentOptions opts;
    opts.out_dir = dir / "a";
    const auto a = run_experiment({t}, opts);
    opts.out_dir = dir / "b";
    const auto b = run_experiment({t}, opts);
    ASSERT_EQ(a.files.size(), 1u);
    EXPECT_EQ(bytes(a.files[0]), bytes(b.files[0]));
    EXPECT_EQ(read_trial_stamp(a.files[0])->fingerprint, t.fingerprint());
    EXPECT_TRUE(trial_file_complete(a.files[0], t));
    // A rerun skips the complete trial; a changed configuration reruns it.
    opts.out_dir = dir / "a";
    EXPECT_EQ(run_experiment({t}, opts).skipped, 1);
    TrialConfig changed = t;
    changed.model.bvc.sigma_phi = 0.02;
    EXPECT_EQ(run_experiment({changed}, opts).ran, 1);
    // Reading back.
    const auto d = read_trial_samples(a.files[0]);
    EXPECT_EQ(d.model, "3d-0.2");
    EXPECT_EQ(d.world, "cross-45");
    EXPECT_EQ(d.tilt_deg, 45.0);
    EXPECT_EQ(d.n_place, 250u);
    EXPECT_EQ(d.rates.size(), d.x.size() * 250);
    const auto s = read_trial_summary(a.files[0], analysis::metric_names());
    EXPECT_EQ(s.metrics.size(), analysis::metric_names().size());
    fs::remove_all(dir);
}

TEST(TrialFiles, BrokenFilesAreNotComplete) {
    const auto dir = temp_dir("broken");
    std::ofstream(dir / "x.h5") << "not hdf5";
    EXPECT_FALSE(read_trial_stamp(dir / "x.h5"));
    EXPECT_FALSE(read_trial_stamp(dir / "missing.h5"));
    EXPECT_THROW(read_trial_samples(dir / "x.h5"), InputError);
    fs::remove_all(dir);
}

TEST(TrialConfigs, NamesAndFingerprints) {
    EXPECT_EQ(trial("3d-3l", 30, 1, 7).name(), "cross-30_3d-3l_seed7");
    EXPECT_EQ(trial("2d").fingerprint(), trial("2d").fingerprint());
    EXPECT_NE(trial("2d").fingerprint(), trial("2d", 45, 0.05, 2).fingerprint());
    EXPECT_NE(trial("2d").fingerprint(), trial("2d", 45, 0.06).fingerprint());
    std::vector<TrialConfig> twins{trial("2d"), trial("2d")};
    ExperimentOptions opts;
    opts.out_dir = fs::temp_directory_path() / "bvc3d-never-written";
    EXPECT_THROW(run_experiment(twins, opts), InputError);
    EXPECT_FALSE(fs::exists(opts.out_dir));
}

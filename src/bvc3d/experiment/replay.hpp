#pragma once
// Replays (docs/recordings.md): a recording — or a simulated sensor standing in for a real one,
// along a given path — run through models as a trial, and localization of one replay's scans
// against another's. Takes: recordings, paths, worlds, models. Gives: trial configurations, the
// rates of every scan, and localization results.
#include <cstdint>
#include <memory>
#include <vector>

#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/analysis/localization.hpp"
#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/experiment/trial_runner.hpp"

namespace bvc3d {

// Where a replay's scans come from and where they were taken.
struct ReplaySource {
    WorldSpec world = WorldSpec::none();
    std::shared_ptr<const ReturnsSpec> returns;
    std::shared_ptr<const TrajectorySpec> path;
};

// A recording: no world, its own poses as the path.
ReplaySource recorded_source(std::shared_ptr<const recording::Recording> recording, const RecordedReturnParams& params);
// A simulated sensor along a path in a world, preprocessed like a recording.
ReplaySource simulated_source(const WorldSpec& world, std::shared_ptr<const TrajectorySpec> path,
                              const LidarSpec& sensor, const RecordedReturnParams& params);

// The trial that replays `source` through `model`: one model step per scan, every step recorded
// with its BVC rates; place cells learn when `learn` (the online protocol), else stay frozen
// (starting from `weights` if given, else from the seed's draw).
TrialConfig replay_trial(const ReplaySource& source, const ModelSpec& model, bool learn,
                         std::shared_ptr<const InitialWeights> weights = nullptr, std::uint64_t seed = 0);

// Replays `source` through every trial's model at once (one group; no analysis, no files).
GroupResult run_replay(const std::vector<TrialConfig>& trials, const RunControl& control = {});

// Rows of a group's rates for one model: BVC rates (recorded by every replay) or place-cell rates,
// with the samples' x, y, z.
struct ReplayRates {
    analysis::RowMatrixXf rates;
    analysis::Points xyz;
};
ReplayRates replay_rates(const GroupResult& result, std::size_t model, bool bvc);

}  // namespace bvc3d

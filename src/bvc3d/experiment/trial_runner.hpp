#pragma once
// Runs trials: the agent's steps, each model's returns, BVC layer and place cells.
// Takes: trial configurations. Gives: the recorded samples and trained weights of each.
//
// A group is several models on one agent in one world with one seed: they share the agent's steps
// (the agent has its own random stream) and each distinct return source is read once per step
// (a ray-cast sensor with the union of the rows the models need); models whose BVC layers differ
// only in their elevations read their sums from one layer that sums the union of their elevations
// once; their place cells are stepped in blocks of steps, model by model, so each model's weights
// stay in cache. Each model's results are bit-identical to running it alone.
#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <vector>

#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/core/cancel.hpp"  // Interrupted: thrown when RunControl::stop is set, after the checkpoint
#include "bvc3d/recorder/trial_record.hpp"
#include "bvc3d/sensor/return_source.hpp"

namespace bvc3d {

struct RunControl {
    const std::atomic<bool>* stop = nullptr;                                     // checked every few steps
    std::function<void(double seconds_done, std::int64_t steps_done)> progress;  // every progress_every steps
    std::int64_t progress_every = 512;  // a replay's steps are few and slow: every step
    std::filesystem::path checkpoint;   // empty: no checkpoints
    double checkpoint_minutes = 0;      // > 0: also every this many simulated minutes
    // Warnings (a checkpoint that cannot be used, ...); default: a line on standard error.
    std::function<void(const std::string& message)> warn;
    bool checkpoint_at_end = false;  // also checkpoint when the run ends (a learning run that more work goes on from)
    bool keep_states = false;        // GroupResult::states: every population's state at the end
};

// Where each model's returns come from (config/returns_spec.hpp): `sources` if given, else the
// trials' `returns`, else each model's sensor ray-cast in the world (models with the same beam table
// share one).

// All trials must share world, seed, protocol, agent and returns (InputError otherwise).
GroupResult run_trial_group(const std::vector<TrialConfig>& trials, const RunControl& control = {});
// The same in a world already built from trials.front().world, or none (null) for a trial without one.
GroupResult run_trial_group(const World* world, const std::vector<TrialConfig>& trials, const RunControl& control = {},
                            const SourceFactory& sources = {});
inline GroupResult run_trial_group(const World& world, const std::vector<TrialConfig>& trials,
                                   const RunControl& control = {}, const SourceFactory& sources = {}) {
    return run_trial_group(&world, trials, control, sources);
}

// Fingerprint of a group: what its checkpoint must match to be resumed.
std::string group_fingerprint(const std::vector<TrialConfig>& trials);

}  // namespace bvc3d

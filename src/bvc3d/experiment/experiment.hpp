#pragma once
// Runs a list of trials into a folder of trial files: the engine under `bvc3d paper` and sweeps.
// Completed trials (a file whose configuration matches) are skipped; the rest run in groups that
// share a walk, in parallel, one group per thread; each finished trial is analysed and written.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "bvc3d/experiment/trial_config.hpp"

namespace bvc3d {

struct ExperimentOptions {
    std::filesystem::path out_dir = "results";
    int jobs = 0;                              // threads; 0: every core
    bool progress = false;                     // a progress line on standard error
    double checkpoint_minutes = 0;             // periodic checkpoints (simulated minutes); 0: on interrupt only
    const std::atomic<bool>* stop = nullptr;   // Ctrl-C: checkpoint and stop
};

struct ExperimentOutcome {
    std::vector<std::filesystem::path> files;  // every trial's file, in the order of the trials
    int ran = 0, skipped = 0;
    std::int64_t steps = 0;                    // model steps simulated in this run (per walk)
    double wall_seconds = 0;
};

std::filesystem::path trial_path(const std::filesystem::path& out_dir, const TrialConfig& t);

// Throws InputError for bad configurations (before anything runs) and Interrupted if stopped.
ExperimentOutcome run_experiment(const std::vector<TrialConfig>& trials, const ExperimentOptions& options);

// Analyses a trial's recorded samples (SPEC §8) with its configured parameters.
analysis::TrialMetrics analyze(const TrialConfig& t, const WorldDescription& world, const std::vector<double>& x,
                               const std::vector<double>& y, const std::vector<float>& rates, int n_place);

}  // namespace bvc3d

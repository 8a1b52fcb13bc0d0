#pragma once
// Experiment engine: runs a list of trials into a folder of trial files (`bvc3d paper`, sweeps).
// Completed trials (a file whose configuration and metrics match) are skipped; the rest run in
// groups that share an agent, in parallel, one group per thread, through the trial pipeline.
#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "bvc3d/config/trial_config.hpp"

namespace bvc3d {

// Progress on standard error: none, one line rewritten in place (a terminal), or plain lines
// (one per finished trial, and one per tenth of the work for long trials: logs and batch jobs).
enum class ProgressStyle { none, terminal, lines };

struct ExperimentOptions {
    std::filesystem::path out_dir = "results";
    int jobs = 0;  // threads; 0: every core
    ProgressStyle progress = ProgressStyle::none;
    double checkpoint_minutes = 0;            // periodic checkpoints (simulated minutes); 0: on interrupt only
    const std::atomic<bool>* stop = nullptr;  // Ctrl-C: checkpoint and stop
    std::function<void(const std::string& name)> on_trial_done;  // called from worker threads
};

// Who runs what. Local runs deal groups to threads from a counter; under MPI, rank 0 decides which
// groups remain and deals them out on request (src/bvc3d/experiment/mpi_coordinator.hpp).
class Coordinator {
public:
    virtual ~Coordinator() = default;
    virtual bool is_root() const { return true; }  // prints progress and writes summaries
    // The root's list of pending groups, given to everyone.
    virtual std::vector<std::size_t> agree(std::vector<std::size_t> pending) { return pending; }
    // The next group (an index into the pending list) for a worker thread; nullopt when none is left.
    virtual std::optional<std::size_t> next() = 0;
    // This process's workers are done; the root returns once every process is.
    virtual void finish() {}
};

struct ExperimentOutcome {
    std::vector<std::filesystem::path> files;  // every trial's file, in the order of the trials
    int ran = 0, skipped = 0;
    std::int64_t steps = 0;        // walk steps simulated in this run (one per group step)
    std::int64_t model_steps = 0;  // model updates: walk steps × models sharing the walk
    double wall_seconds = 0;
};

std::filesystem::path trial_path(const std::filesystem::path& out_dir, const TrialConfig& t);

// Bytes a run of these trials needs at its peak with `jobs` groups at once (0: every core): the
// recorded samples, weights, analysis and file images of the largest groups. An estimate, for
// refusing runs that cannot fit (core/memory.hpp) before they start.
double estimate_memory(const std::vector<TrialConfig>& trials, int jobs);

// Throws InputError for bad configurations (before anything runs) and Interrupted if stopped.
// Without a coordinator, options.jobs threads share the work.
ExperimentOutcome run_experiment(const std::vector<TrialConfig>& trials, const ExperimentOptions& options,
                                 Coordinator* coordinator = nullptr);

}  // namespace bvc3d

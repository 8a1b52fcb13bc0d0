#pragma once
// Runs trials (SPEC §7): the random walk, the sensors, and each model's BVC layer and place cells.
// Takes: trial configurations. Gives: the recorded samples and trained weights of each.
//
// A group is several models in one world with one seed: they share one walk (the walk has its
// own random stream) and each distinct sensor is cast once per step, with the union of the rows
// the models need. Each model's results are bit-identical to running it alone.
#include <atomic>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <vector>

#include "bvc3d/experiment/trial_config.hpp"
#include "bvc3d/recorder/trial_record.hpp"

namespace bvc3d {

// Thrown when RunControl::stop is set; the group's checkpoint (if any) was written first.
class Interrupted : public std::runtime_error {
public:
    Interrupted() : std::runtime_error("interrupted") {}
};

struct RunControl {
    const std::atomic<bool>* stop = nullptr;            // checked every few steps
    std::function<void(double seconds_done, std::int64_t steps_done)> progress;  // every few hundred steps
    std::filesystem::path checkpoint;                   // empty: no checkpoints
    double checkpoint_minutes = 0;                      // > 0: also every this many simulated minutes
};

// All trials must share world, seed, protocol and robot (InputError otherwise).
GroupResult run_trial_group(const std::vector<TrialConfig>& trials, const RunControl& control = {});

// Fingerprint of a group: what its checkpoint must match to be resumed.
std::string group_fingerprint(const std::vector<TrialConfig>& trials);

}  // namespace bvc3d

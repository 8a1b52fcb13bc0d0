#pragma once
// YAML sweeps: a base trial, a grid over any of its keys (and/or an explicit list of conditions),
// and seeds. Schema in docs/sweeps.md; examples in configs/sweeps/.
#include <string>
#include <vector>

#include "bvc3d/config/trial_config.hpp"

namespace bvc3d::config {

struct Sweep {
    std::string name;
    std::vector<std::string> keys;    // the swept keys, in the order of the file
    std::vector<TrialConfig> trials;  // every condition × seed, conditions in grid order
};

// The most trials a sweep (conditions × seeds) or `bvc3d paper` may list: counted before any is
// built, so that a mistaken grid is refused at once with its size.
inline constexpr double max_trials = 100000;

// Throws ConfigError naming the file, the key and the reason (unknown keys, empty grids, values
// of the wrong type, impossible values, too many trials, ...).
Sweep load_sweep_file(const std::string& path);

}  // namespace bvc3d::config

#pragma once
// Report stage: navigation's tables (docs/navigation.md#outputs) from navigation trial files. Takes: the trials'
// /navigation groups (recorder/trial_file.hpp) with a label each for its world and model. Gives: starts.csv (one row
// per start), paths.csv (every position of every start), reward_map.csv, learning.csv, and summary.csv / summary.md
// (per model and goal: starts, success rate, the path ratio's median and quartiles over the successes, learning
// hours). Numbers in CSVs are exact (the shortest text that reads back to the same double); figures are drawn by
// the Python module bvc3d.navigation_figures from these files.
#include <filesystem>
#include <string>
#include <vector>

#include "bvc3d/recorder/trial_file.hpp"

namespace bvc3d {

struct NavigationTrial {
    std::string world, model;  // labels for the tables: the world and the model as the user named them
    std::uint64_t seed = 0;
    NavigationRecord record;
};

// The trial file's navigation and its labels: the world and model a command named (the trial's swept values
// `world` and `model` when it has them), else the trial's own labels.
NavigationTrial read_navigation_trial(const std::filesystem::path& file);

// The trials' tables in `folder` (atomically, each file whole or absent), rows in the order of `trials`; the summary
// has a row per world, model and goal in the order they first appear. InputError if goals on the floor and in 3-D
// would share a table.
void write_navigation_report(const std::filesystem::path& folder, const std::vector<NavigationTrial>& trials);

// The q-quantile of v by linear interpolation between order statistics (numpy's default); NaN for none.
double quantile(std::vector<double> v, double q);

}  // namespace bvc3d

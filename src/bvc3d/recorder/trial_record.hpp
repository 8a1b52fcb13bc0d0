#pragma once
// Recorder stage: what a trial records, in memory (trial_file.hpp writes it to HDF5,
// checkpoint_file.hpp saves a running one).
// Takes: each model step's time and pose and each model's rates. Gives: the arrays of a trial.
#include <cstdint>
#include <string>
#include <vector>

#include "bvc3d/population/population.hpp"

namespace bvc3d {

// A population of a model other than its BVC layer and place cells (population/population.hpp).
struct PopulationRecord {
    std::string name;
    std::size_t cells = 0;
    bool recorded = false;
    std::vector<float> rates;      // samples × cells, row-major, if recorded
    std::vector<StateArray> kept;  // what the trial keeps of it at the end
};

// A model's records: its place cells and BVC layer (the paper's network), and its other populations.
struct ModelRecord {
    std::vector<float> rates;    // samples × n_place, row-major
    std::vector<float> bvc;      // samples × n_bvc, if the protocol records them
    std::vector<float> weights;  // n_place × n_bvc
    int n_place = 0, n_bvc = 0;
    std::vector<PopulationRecord> populations;
};

struct WalkStats {
    std::int64_t explore_steps = 0, sample_steps = 0, bumps = 0, full_scan_fallbacks = 0;
    double end_time = 0;  // seconds of agent time at the end
};

// A group of models on one agent's steps: the samples' poses are shared, the records are per model.
struct GroupResult {
    std::vector<double> t, x, y, z, heading;  // one per recorded sample
    std::vector<ModelRecord> models;          // in the order of the group's trials
    WalkStats stats;
};

// Everything needed to continue a group exactly where it stopped.
struct GroupCheckpoint {
    std::string fingerprint;  // of the group's configuration
    std::string agent_state;  // Agent::save_state()
    std::int64_t step_index = 0;
    GroupResult partial;                          // samples (see below); the models' records give their shapes
    std::vector<std::vector<StateArray>> states;  // per population of the group's network, in its order
    // On disk the samples sit in `segments` files holding the first `saved` of them. When writing,
    // `partial` holds only the samples after those; when read back, all of them.
    std::size_t segments = 0, saved = 0;
};

}  // namespace bvc3d

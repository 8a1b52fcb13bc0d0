#pragma once
// Recorder stage: what a trial records, in memory (trial_file.hpp writes it to HDF5,
// checkpoint_file.hpp saves a running one).
// Takes: each model step's time and pose and each model's rates. Gives: the arrays of a trial.
#include <cstdint>
#include <string>
#include <utility>
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

// What a navigation trial records after its learning run (SPEC §17, experiment/episodes.hpp): the learning walk's
// end, the reward cells, each start and its path, and the first scale's reward map. Goals are numbered from 1 in
// files and messages (goal_text) and stored in order here.
struct NavigationRecord {
    int dims = 2;                     // coordinates of goals, starts and paths: 2 on the floor, 3 flying
    std::vector<double> goals;        // goals × dims
    double learn_s = 0;               // simulated seconds of learning
    double coverage = 0;              // of the free cells, reached
    std::vector<int> visits;          // per goal, entries into its radius while learning
    std::vector<std::string> scales;  // the place-cell scales' names
    std::vector<int> goal_cells;      // scales × goals: each scale's reward cell, -1 if none was bound
    // One entry per start, in the order they ran (goal by goal).
    std::vector<int> start_goal;  // index into the goals
    std::vector<double> start;    // starts × dims
    std::vector<int> success;     // 1 if it reached the goal
    std::vector<double> path_m, shortest_m, time_s;
    std::vector<std::uint64_t> path_start;  // starts + 1 offsets into `path`
    std::vector<double> path;               // points × dims: each start's positions, its start first
    // Why each start failed (navigation/failure_class.hpp: 0 reached, then blocked, closing-in, plateau, wrong-basin,
    // loop, wander); empty in files written before the classes existed.
    std::vector<int> failure;
    // The floor's geometry in the body's slab as segments (x0, y0, x1, y1), for figures; none in flight.
    std::vector<double> walls;
    // The first scale's reward read-out at points of the floor (none in flight): points × 2, and goals × points.
    std::vector<double> map_points, map_reward;
    std::size_t n_goals() const { return dims > 0 ? goals.size() / std::size_t(dims) : 0; }
    std::size_t n_starts() const { return start_goal.size(); }
};

// A model's records: its place cells and BVC layer (the paper's network), and its other populations.
struct ModelRecord {
    std::vector<float> rates;    // samples × n_place, row-major
    std::vector<float> bvc;      // samples × n_bvc, if the protocol records them
    std::vector<float> weights;  // n_place × n_bvc
    int n_place = 0, n_bvc = 0;
    std::vector<PopulationRecord> populations;
    std::vector<NavigationRecord> navigation;  // one for a navigation trial, after its episodes
};

struct WalkStats {
    std::int64_t explore_steps = 0, sample_steps = 0, bumps = 0, full_scan_fallbacks = 0;
    double end_time = 0;                                       // seconds of agent time at the end
    std::vector<std::pair<std::string, double>> agent_report;  // Agent::report() at the end
};

// A group of models on one agent's steps: the samples' poses are shared, the records are per model.
struct GroupResult {
    std::vector<double> t, x, y, z, heading;  // one per recorded sample
    std::vector<ModelRecord> models;          // in the order of the group's trials
    WalkStats stats;
    // Every population's state at the end, in the order of the group's network (RunControl::keep_states).
    std::vector<std::vector<StateArray>> states;
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

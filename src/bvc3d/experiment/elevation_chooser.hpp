#pragma once
// Adaptive elevations (docs/adaptive.md): the agent chooses its BVC layers' elevations from its own
// short exploratory walk. The criterion of a candidate set of elevations is the place-cell aliasing
// (MSAI) its network produces on that walk: learning on one pass of the walk, then a frozen second
// pass over the same poses and scans, analyzed as a trial is. Every candidate reads the one walk
// and, per step, one shared scan (the trial runner shares sources between models).
// Takes: a world, a base model (its sensor, σs, n_dir, place cells), an agent, a BVC budget and a
// candidate range. Gives: the criterion of every candidate set considered and the chosen set.
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "bvc3d/agent/agent.hpp"
#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/core/params.hpp"
#include "bvc3d/experiment/replay.hpp"
#include "bvc3d/experiment/trial_runner.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

// The most candidate elevations a search considers (each is a short trial in every round): an
// elevation_step of 0.003 rad over the whole sphere.
inline constexpr double max_candidate_elevations = 1000;

struct ChooserParams {
    int budget = 960;            // BVCs shared by the layers: n_per_axis = budget / (n_dir · layers)
    int min_layers = 1;          // the greedy search adds layers up to at least this many...
    int max_layers = 4;          // ...and stops here or when a layer no longer lowers the criterion
    double elevation_min = 0.0;  // rad, candidate elevations: min, min + step, ... ≤ max
    double elevation_max = 0.4;
    double elevation_step = 0.05;
    double explore_minutes = 30;              // simulated minutes of the exploratory walk
    std::uint64_t seed = 0;                   // the walk's seed (and the candidates' initial weights)
    int jobs = 0;                             // threads the candidates are split between; 0: every core
    const std::atomic<bool>* stop = nullptr;  // when set: Interrupted within a few steps

    static const params::Table<ChooserParams>& table();
    // InputError for impossible values, an empty candidate range, or a budget too small for the layers.
    void validate(int n_dir = BvcParams{}.n_dir) const;
    std::vector<double> candidate_elevations() const;
};

// What an agent explores with unless told otherwise: the ground robot the paper's spherical scanner
// and the 0.2-rad model's cells (3d-0.2), candidates from 0 up; a flying agent its full spherical
// scanner at the body's center and fly-5l's cells, candidates looking down as far as up.
struct ChooserDefaults {
    const char* model;
    const char* sensor;
    bool symmetric_range;  // elevation_min = -elevation_max
};
ChooserDefaults chooser_defaults(const AgentSpec& agent);

struct CandidateScore {
    std::vector<double> elevations;
    int n_per_axis = 0;
    int round = 0;               // the greedy round (= number of layers) that considered it
    double msai = 0;             // the criterion: lower is better
    double frac_multimodal = 0;  // shown beside it, not used to choose
    double bvc_msai = 0;         // the same MSAI over the BVC population's rate maps on the same
                                 // bins: the input's aliasing, shown, not used (docs/adaptive.md)
};

struct ElevationChoice {
    ModelSpec model;  // the base model with the chosen layers
    CandidateScore chosen;
    std::vector<CandidateScore> candidates;  // every set considered, in the order considered
    std::size_t walk_steps = 0;
};

// The exploratory walk: the agent's model steps, and whether its positions are analyzed in the
// plane (2, the ground robot) or in space (3, a flying agent: voxels, as its trials are).
struct ExplorationWalk {
    std::vector<ModelStep> steps;
    int dims = 2;
};

// The agent's model steps over `minutes` of its time (one walk, its own seed). InputError if no two
// positions lie farther apart than d_th (in the agent's dimensions; nothing to measure aliasing on).
ExplorationWalk exploration_walk(const World& world, const AgentSpec& agent, std::uint64_t seed, double minutes,
                                 double d_th);

// The base model with these layers and the budget's n_per_axis (InputError if fewer than 2).
ModelSpec model_with_elevations(const ModelSpec& base, const std::vector<double>& elevations, int budget);

// The criterion of each elevation set on one walk. `sources` gives each model's returns by walk
// step (e.g. recorded scans; default: the model's sensor ray-cast in `world`; called from worker
// threads); the second pass reads the same steps again. `jobs` threads share the sets (0: every core).
// `stop`, when set, ends the runs with Interrupted.
std::vector<CandidateScore> score_elevation_sets(const World* world, const ModelSpec& base, const ExplorationWalk& walk,
                                                 const std::vector<std::vector<double>>& sets, int budget,
                                                 std::uint64_t seed, const analysis::AnalysisParams& analysis,
                                                 int jobs = 0, const SourceFactory& sources = {},
                                                 const std::atomic<bool>* stop = nullptr);
inline std::vector<CandidateScore> score_elevation_sets(const World& world, const ModelSpec& base,
                                                        const ExplorationWalk& walk,
                                                        const std::vector<std::vector<double>>& sets, int budget,
                                                        std::uint64_t seed, const analysis::AnalysisParams& analysis,
                                                        int jobs = 0, const SourceFactory& sources = {},
                                                        const std::atomic<bool>* stop = nullptr) {
    return score_elevation_sets(&world, base, walk, sets, budget, seed, analysis, jobs, sources, stop);
}

// The greedy search: round 1 scores each candidate elevation alone; each later round adds one
// elevation (not yet in the set) to the round's best. Deterministic: ties go to the set considered first.
ElevationChoice choose_elevations(const World& world, const ModelSpec& base, const AgentSpec& agent,
                                  const ChooserParams& params, const analysis::AnalysisParams& analysis = {},
                                  const SourceFactory& sources = {});

// The best of the given sets (each scored on one walk; params' budget, walk and seed apply, its
// layer counts and candidate range do not).
ElevationChoice choose_from_sets(const World& world, const ModelSpec& base, const AgentSpec& agent,
                                 const std::vector<std::vector<double>>& sets, const ChooserParams& params,
                                 const analysis::AnalysisParams& analysis = {}, const SourceFactory& sources = {});

// "0, 0.25" — elevations as a model YAML and tables show them.
std::string elevations_text(const std::vector<double>& elevations);

// The choice on recorded scans (or a simulated stand-in, replay.hpp): the source's path is the
// exploratory walk and its scans the returns (step i reads scan i), so no world is needed and
// nothing is cast. `sets` empty: the greedy search; else the best of these sets. params'
// explore_minutes does not apply (the recording is the walk); its seed draws the initial weights.
ElevationChoice choose_elevations_on(const ReplaySource& source, const ModelSpec& base, const ChooserParams& params,
                                     const analysis::AnalysisParams& analysis = {},
                                     const std::vector<std::vector<double>>& sets = {});

}  // namespace bvc3d

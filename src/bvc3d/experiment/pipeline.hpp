#pragma once
// The trial pipeline, one for every way of running trials (`bvc3d run`, `paper`, `sweep`, Python's
// run_trial): run a group of trials on one agent, analyze each, and write each trial file.
// Takes: trial configurations (and file paths). Gives: their results, metrics and files.
#include <filesystem>
#include <vector>

#include "bvc3d/analysis/trial_metrics.hpp"
#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/experiment/trial_runner.hpp"
#include "bvc3d/recorder/trial_file.hpp"

namespace bvc3d {

struct AnalyzedPopulation {
    analysis::TrialMetrics metrics;
    analysis::AnalysisParams params;  // what the metrics were computed with (extent resolved)
};
// The name under which a multiscale model's scales, fused, are analysed (pipeline.cpp's analyze).
inline constexpr const char* fused_population = "place-fused";
// A trial's metrics: of its place cells, and of each other recorded population (by name).
struct AnalyzedTrial : AnalyzedPopulation {
    std::vector<std::pair<std::string, AnalyzedPopulation>> populations;
};

struct GroupOutcome {
    GroupResult result;
    std::vector<AnalyzedTrial> trials;  // in the order of the group's trials
};

// Runs the group (sharing one agent) and analyzes each trial; a navigation trial's episodes run after its learning
// (episodes.hpp) and its record is in the result's model record.
GroupOutcome run_and_analyze(const std::vector<TrialConfig>& trials, const RunControl& control = {});
// The same in a world already built from trials.front().world, or none (null) for a trial without one.
GroupOutcome run_and_analyze(const World* world, const std::vector<TrialConfig>& trials,
                             const RunControl& control = {});
// The same, then writes trial k to paths[k] (atomically) and removes the group's checkpoint.
GroupOutcome run_analyze_write(const std::vector<TrialConfig>& trials, const std::vector<std::filesystem::path>& paths,
                               const RunControl& control = {});

// The recorded positions as N × dims: x, y (and z for 3-D agents).
analysis::Points sample_positions(const GroupResult& r, int dims);
// Analyzes one model of a group's result with the trial's parameters.
AnalyzedTrial analyze(const TrialConfig& t, const WorldDescription& world, const GroupResult& result,
                      std::size_t model);

// What a trial file records of a trial: its identity and configuration, and its metrics.
TrialIdentity trial_identity(const TrialConfig& t, const WorldDescription& world);
// `scalars` false: the scalar metrics are left out (untrained place cells: TrialConfig::place_cells_untrained).
MetricsRecord metrics_record(const analysis::TrialMetrics& m, const analysis::AnalysisParams& params,
                             bool scalars = true);
// The analysis parameters a trial file's metrics were computed with (defaults for what it lacks);
// a stored value of the wrong type or out of its limits is an InputError naming `path` and the key.
analysis::AnalysisParams stored_analysis_params(const TrialFileData& file, const std::filesystem::path& path);
// The bounds of the walkable region of the trial's world (its `world_source` and `tilt_deg`), for
// `--extent arena`; an InputError naming `path` when the world cannot be found again.
analysis::Extent arena_extent(const TrialFileData& file, const std::filesystem::path& path);

// True if `path` holds this trial, complete, with every metric the analysis stage now reports.
bool trial_file_complete(const std::filesystem::path& path, const TrialConfig& t);

}  // namespace bvc3d

#pragma once
// Trial files (SPEC §9): one HDF5 file per trial with the configuration as attributes, the
// recorded samples, the trained weights and the metrics. The layout is in docs/trial-files.md.
#include <filesystem>
#include <optional>
#include <string>

#include "bvc3d/analysis/trial_metrics.hpp"
#include "bvc3d/experiment/trial_config.hpp"
#include "bvc3d/recorder/trial_record.hpp"

namespace bvc3d {

inline constexpr int trial_file_format_version = 1;

// Writes the file atomically: it appears only when complete.
// `params` are the analysis parameters the metrics were computed with; they are stored with them.
void write_trial_file(const std::filesystem::path& path, const TrialConfig& config, const GroupResult& group,
                      std::size_t model_index, const analysis::TrialMetrics& metrics,
                      const analysis::AnalysisParams& params);

// The fingerprint of a complete trial file, or nullopt if it is missing, broken or not a trial file.
std::optional<std::string> trial_file_fingerprint(const std::filesystem::path& path);

// Which trial a file holds.
struct TrialIdentity {
    std::string name, condition, world, model;
    std::vector<std::pair<std::string, std::string>> swept;  // the condition's defining values
    std::uint64_t seed = 0;
    double tilt_deg = NAN;  // cross arenas only
};

// What `bvc3d analyze` reads back.
struct TrialFileData : TrialIdentity {
    std::string protocol, config;
    analysis::AnalysisParams analysis;  // the parameters its metrics were computed with (defaults if unrecorded)
    std::vector<double> x, y;
    analysis::RowMatrixXf rates;  // samples × cells
};
TrialFileData read_trial_samples(const std::filesystem::path& path);  // throws InputError

// The scalar metrics stored in a trial file, by name (for summaries).
struct TrialSummaryRow : TrialIdentity {
    std::vector<std::pair<std::string, double>> metrics;
};
TrialSummaryRow read_trial_summary(const std::filesystem::path& path);  // throws InputError

// The scalar metrics of an analysis (stored as attributes of /metrics), in the order summaries print them.
const std::vector<std::string>& scalar_metric_names();
std::vector<std::pair<std::string, double>> scalar_metrics(const analysis::TrialMetrics& m);

}  // namespace bvc3d

#pragma once
// Report stage (C++ side): the experiment summary, one row per condition with every metric's
// mean ± sd over seeds, as CSV and as a Markdown table. Figures are drawn by the Python module
// bvc3d.report, which reads these files and the trial files.
// Takes: trial files (recorder) and the metric table (analysis). Gives: trials.csv, summary.csv/.md.
#include <filesystem>
#include <string>
#include <vector>

#include "bvc3d/recorder/trial_file.hpp"

namespace bvc3d {

struct SummaryRow {
    std::string condition, model, world;
    std::vector<std::pair<std::string, std::string>> swept;
    double tilt_deg = NAN;
    int n_seeds = 0;
    std::vector<std::string> metric_names;
    std::vector<double> mean, sd;  // sd over seeds (n - 1); NaN for one seed
};

// Rows in the order conditions first appear in `trials`.
std::vector<SummaryRow> summarize(const std::vector<TrialSummaryRow>& trials);
// Every metric of the analysis stage's table and the analysis parameters, from each file (NaN where
// a file predates a metric). A file that cannot be read is an InputError naming it.
TrialSummaryRow read_summary(const std::filesystem::path& file);
std::vector<TrialSummaryRow> read_summaries(const std::vector<std::filesystem::path>& files);

// Why these trials should not share one table, or "" if they may: they must agree on the protocol,
// its durations and every analysis parameter, except where a trial's swept keys make the
// difference the point (a sweep over protocol.sample_hours); within one condition, always.
std::string mixing_problem(const std::vector<TrialSummaryRow>& trials, const std::vector<std::filesystem::path>& files);

// Written atomically. The CSV has columns condition, model, world, tilt_deg, swept:<key>..., n_seeds,
// <metric>_mean, <metric>_sd; the Markdown table shows the swept keys (or model and world).
void write_summary_csv(const std::filesystem::path& path, const std::vector<SummaryRow>& rows);
void write_summary_markdown(const std::filesystem::path& path, const std::vector<SummaryRow>& rows);
// One row per trial: name, condition, model, world, tilt_deg, swept:<key>..., seed, protocol,
// explore_hours, sample_hours, <metric>...
void write_trials_csv(const std::filesystem::path& path, const std::vector<TrialSummaryRow>& trials);

}  // namespace bvc3d

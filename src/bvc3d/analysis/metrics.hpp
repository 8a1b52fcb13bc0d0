#pragma once
// The scalar metrics of a trial: one table (name, headings, format), read by everyone who shows or
// stores them — trial files, summaries, the command line and the Python report.
// Takes: TrialMetrics. Gives: named values in the table's order.
#include <string>
#include <utility>
#include <vector>

#include "bvc3d/analysis/trial_metrics.hpp"

namespace bvc3d::analysis {

struct Metric {
    const char* name;     // attribute in trial files, column in tables
    const char* heading;  // column heading in summary.md
    const char* label;    // axis label in figures
    const char* title;    // figure title; "" for metrics without a figure of their own
    int digits;           // decimals in summary.md; -1 for metrics summary.md leaves out
    double (*value)(const TrialMetrics&);
    int dims = 0;  // 0: every trial; 3: trials of 3-D positions only (flying agents)
    bool applies(int trial_dims) const { return dims == 0 || dims == trial_dims; }
};

const std::vector<Metric>& metric_table();
// The metrics a trial of `dims`-coordinate positions reports (every metric: dims 0).
std::vector<std::string> metric_names(int dims = 0);
std::vector<std::pair<std::string, double>> scalar_metrics(const TrialMetrics& m);

}  // namespace bvc3d::analysis

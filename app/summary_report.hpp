#pragma once
// The tables and figures of a folder of trial files, as `paper`, `flight`, `sweep` and `summarize`
// write them: trials.csv, summary.csv/.md (report/summary.hpp) and the figures and report.md (the
// Python module bvc3d.report, run as a child process).
#include <filesystem>
#include <vector>

namespace bvc3d::cli {

// trials.csv, summary.csv/.md and (with `report`) the figures for a folder of trial files. Trials
// whose protocol, durations or analysis parameters differ (report/summary.hpp) are refused unless
// `allow_mixed`. A failed report leaves no half-written figure and says why.
void summarize(const std::filesystem::path& out, const std::vector<std::filesystem::path>& files, bool report,
               bool allow_mixed = false);

}  // namespace bvc3d::cli

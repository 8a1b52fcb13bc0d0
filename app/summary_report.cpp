#include "summary_report.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <string>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recorder/trial_file.hpp"
#include "bvc3d/report/navigation_report.hpp"
#include "bvc3d/report/summary.hpp"
#include "cli_common.hpp"
#include "python_module.hpp"

namespace bvc3d::cli {

namespace {

// True if a PNG file is complete (ends with its IEND chunk).
bool png_complete(const std::filesystem::path& file) {
    static const char iend[] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', '\xae', '\x42', '\x60', '\x82'};
    std::ifstream in(file, std::ios::binary | std::ios::ate);
    if (!in || in.tellg() < 12) return false;
    in.seekg(-12, std::ios::end);
    char tail[12];
    return static_cast<bool>(in.read(tail, 12)) && std::equal(tail, tail + 12, iend);
}

// After a failed report: nothing half-written stays. Temporary files, and figures that do not end
// where a PNG ends, are removed (and returned); complete figures stay.
std::vector<std::filesystem::path> remove_partial_report(const std::filesystem::path& dir) {
    std::vector<std::filesystem::path> removed;
    std::error_code ec;
    for (const auto& folder : {dir, dir / "figures"}) {
        if (!std::filesystem::is_directory(folder, ec)) continue;
        for (const auto& e : std::filesystem::directory_iterator(folder, ec)) {
            const auto name = e.path().filename().string();
            // The report's own temporaries ("report.md.tmp") and ours ("x.csv.tmp<pid>-<n>").
            const auto at = name.rfind(".tmp");
            const bool temporary =
                at != std::string::npos && name.find_first_not_of("0123456789-", at + 4) == std::string::npos;
            const bool broken_png = e.path().extension() == ".png" && !png_complete(e.path());
            if (e.is_regular_file(ec) && (temporary || broken_png) && std::filesystem::remove(e.path(), ec))
                removed.push_back(e.path());
        }
    }
    return removed;
}

// Why a report failed, from its last line: Python's "OSError: [Errno 28] No space left on device"
// becomes "cannot write 'DIR/figures/msai.png': No space left on device" (the file from the error,
// or the half-written figure that was removed). Empty `os_error` for any other failure.
std::string report_failure(const ModuleRun& run, const std::vector<std::filesystem::path>& removed, bool& os_error) {
    const std::string line = run.last_error_line();
    const auto errno_at = line.find("[Errno ");
    const auto close = errno_at == std::string::npos ? std::string::npos : line.find("] ", errno_at);
    os_error = close != std::string::npos;
    if (os_error) {
        std::string reason = line.substr(close + 2), file;
        const auto quote = reason.find(": '");
        if (quote != std::string::npos && reason.back() == '\'') {
            file = reason.substr(quote + 3, reason.size() - quote - 4);
            reason.resize(quote);
        } else if (!removed.empty()) {
            file = removed.front().string();
        }
        return file.empty() ? "writing the figures failed: " + reason : "cannot write '" + file + "': " + reason;
    }
    if (run.status < 0) return "the report process could not run or was killed";
    return line.empty() ? "the report exited with status " + std::to_string(run.status) : printable(line);
}

}  // namespace

namespace {

// Navigation trials' tables (report/navigation_report.hpp) and figures (bvc3d.navigation_figures).
void summarize_navigation(const std::filesystem::path& out, const std::vector<std::filesystem::path>& files,
                          bool report) {
    std::vector<NavigationTrial> trials;
    for (const auto& f : files) trials.push_back(read_navigation_trial(f));
    write_navigation_report(out, trials);
    std::string sources;
    for (const auto& f : files) sources += (sources.empty() ? "" : ", ") + f.filename().string();
    std::printf(
        "wrote starts.csv, paths.csv, learning.csv, reward_map.csv, summary.csv, summary.md in %s from its trial "
        "files (%s)\n",
        out.string().c_str(), sources.c_str());
    if (!report) return;
    const ModuleRun fig = run_python_module("bvc3d.navigation_figures", {out.string(), trials.front().world}, true);
    if (fig.status != 0) std::fprintf(stderr, "bvc3d: warning: no figures (%s)\n", fig.last_error_line().c_str());
}

}  // namespace

void summarize(const std::filesystem::path& out, const std::vector<std::filesystem::path>& files, bool report,
               bool allow_mixed) {
    std::size_t navigating = 0;
    for (const auto& f : files) {
        const auto stamp = read_trial_stamp(f);
        navigating += stamp && stamp->navigation;
    }
    if (navigating > 0 && navigating < files.size())
        throw InputError(
            "navigation trials and trials that record place cells in one folder: one table cannot hold "
            "both (summarize them apart)");
    if (navigating > 0) return summarize_navigation(out, files, report);
    const auto trials = read_summaries(files);
    if (const auto problem = mixing_problem(trials, files); !problem.empty() && !allow_mixed)
        throw InputError(problem + "; one table would mix them (summarize them apart, or pass --allow-mixed)");
    const auto rows = summarize(trials);
    write_trials_csv(out / "trials.csv", trials);
    write_summary_csv(out / "summary.csv", rows);
    write_summary_markdown(out / "summary.md", rows);
    if (!report) return;
    const ModuleRun run = run_python_module("bvc3d.report", {out.string()}, true);
    if (run.status == 0) {
        std::fputs(run.error_text.c_str(), stderr);  // the report's own warnings
        return;
    }
    const auto removed = remove_partial_report(out);
    bool os_error = false;
    const std::string why = report_failure(run, removed, os_error);
    if (!os_error) std::fputs(run.error_text.c_str(), stderr);  // a bug's traceback is worth showing
    throw InputError("the report (figures) failed: " + why + "; the trial files and summary are in '" + out.string() +
                     "'; rerun it with:\n  " + python_command().shell_line("bvc3d.report", {out.string()}));
}

}  // namespace bvc3d::cli

#pragma once
// Helpers shared by the bvc3d subcommands.
#include <CLI/CLI.hpp>

#include <atomic>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "bvc3d/analysis/types.hpp"
#include "bvc3d/core/geometry.hpp"
#include "bvc3d/experiment/experiment.hpp"

namespace bvc3d::cli {

// "X,Y,HEADING": meters and radians, a pose on the floor; the heading may end in "deg" for degrees.
Pose parse_pose(const std::string& text);

// How a module of the Python package runs: the interpreter (BVC3D_PYTHON, else the one found at
// build time) and the PYTHONPATH that finds the package (BVC3D_PYTHONPATH, else the build's python
// folder, then any PYTHONPATH already set).
struct PythonCommand {
    std::string python, pythonpath;
    // The command as a shell line that works as printed: `PYTHONPATH=... /usr/bin/python3 -m MODULE ARGS`.
    std::string shell_line(const std::string& module, const std::vector<std::string>& args) const;
};
PythonCommand python_command();

// Runs `python3 -m MODULE ARGS...` (the package's figure modules) as a child process, no shell;
// returns its exit status.
int run_python_module(const std::string& module, const std::vector<std::string>& args);

// Full-precision decimal text for numbers written to CSV.
std::string num(double v);

// Prints a warning when a pose puts the robot's body inside or against geometry, or outside the
// walkable region: scans from there are legal but rarely what was meant.
void warn_if_blocked(const World& world, const Pose& pose);

// A finite number (std::from_chars: no spaces, no trailing text); `what` names it in the error.
double parse_number(const std::string& text, const std::string& what);

// Text safe to print: invalid UTF-8 and control characters (newlines and tabs aside) become '?'.
std::string printable(std::string_view text);

// Option checks with short messages: seeds are whole numbers 0 .. 2^64 - 1, durations numbers >= 0.
extern const CLI::Validator seed_check;
extern const CLI::Validator non_negative_check;

// `--extent`, the same flag with the same values in run, paper and analyze: `data` (the
// trajectory's own bounds), `arena` (the walkable region's) or XMIN,XMAX,YMIN,YMAX.
struct ExtentOption {
    enum class Kind { data, arena, bounds } kind = Kind::data;
    analysis::Extent bounds;
};
ExtentOption parse_extent(const std::string& text);
extern const char* const extent_help;
// The trial's analysis extent as the option sets it.
void apply_extent(const ExtentOption& e, TrialConfig& t);

// `--jobs`: threads; 0 means one per core. Refuses negative values and more than max_jobs.
inline constexpr int max_jobs = 4096;
int check_jobs(int jobs);

// Refuses (InputError) a run whose estimated memory exceeds what the machine has available,
// unless `skip` (--no-memory-check).
void check_run_memory(const std::vector<TrialConfig>& trials, int jobs, bool skip);
extern const char* const no_memory_check_help;

// Ctrl-C handling shared by the long-running commands: the flag the SIGINT handler sets, a guard
// that installs the handler, and the clean exit (status 130).
std::atomic<bool>& stop_flag();
struct InterruptGuard {
    InterruptGuard();
    ~InterruptGuard();
};
[[noreturn]] void exit_interrupted();

// How a progress report looks: a line rewritten in place on a terminal, else one line per
// finished trial (and now and then for long ones), so that logs show where a run is.
ProgressStyle progress_style();

// Runs trials on this machine's threads into `out` (which the caller has locked), with progress on
// standard error; Ctrl-C or SIGTERM checkpoints and exits with status 130.
struct LocalRun {
    int jobs = 0;
    double checkpoint_minutes = 0;
    bool no_memory_check = false;
    std::function<void(const std::string&)> on_done;
};
ExperimentOutcome run_local_experiment(const std::vector<TrialConfig>& trials, const std::filesystem::path& out,
                                       const LocalRun& how);

// "N trials in DIR (R run, S already complete) in T s, ... steps/s".
void print_outcome(std::size_t n_trials, const std::filesystem::path& out, const ExperimentOutcome& outcome);

// trials.csv, summary.csv/.md and (with `report`) the figures for a folder of trial files. Trials
// whose protocol, durations or analysis parameters differ (report/summary.hpp) are refused unless
// `allow_mixed`. A failed report leaves no half-written figure and says why.
void summarize(const std::filesystem::path& out, const std::vector<std::filesystem::path>& files, bool report,
               bool allow_mixed = false);

void add_simulator_commands(CLI::App& app);
void add_model_commands(CLI::App& app);
void add_experiment_commands(CLI::App& app);
void add_sweep_command(CLI::App& app);
void add_flight_command(CLI::App& app);
void add_recording_commands(CLI::App& app);
void add_view_command(CLI::App& app);               // view/cmd_view.cpp
void add_adaptive_command(CLI::App& app);           // cmd_adaptive.cpp
void add_place_recognition_command(CLI::App& app);  // cmd_place_recognition.cpp
void add_route_command(CLI::App& app);              // cmd_route.cpp

}  // namespace bvc3d::cli

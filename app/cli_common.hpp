#pragma once
// Helpers every bvc3d subcommand may use: reading option values (numbers, poses, lists, extents),
// printing safely, and Ctrl-C handling. What commands that run trials share is in run_options.hpp,
// the Python modules they call in python_module.hpp.
#include <CLI/CLI.hpp>

#include <atomic>
#include <string>
#include <string_view>
#include <vector>

#include "bvc3d/analysis/types.hpp"
#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/core/geometry.hpp"
#include "bvc3d/experiment/experiment.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d::cli {

// The items of a comma-separated value. Lists (`--models 2d,3d-0.2`) skip empty items ("a,,b," is
// a, b); fields (`--pose X,Y,HEADING`) keep them, so that a count of fields can be checked.
enum class EmptyItems { skip, keep };
std::vector<std::string> split_commas(const std::string& text, EmptyItems empty = EmptyItems::skip);

// "X,Y,HEADING": meters and radians, a pose on the floor; the heading may end in "deg" for degrees.
Pose parse_pose(const std::string& text);

// Full-precision decimal text for numbers written to CSV.
std::string num(double v);

// Refuses --seeds below 1, and more trials than a sweep may hold (--seeds × each factor: a count and
// what it counts, "models"), naming --seeds, the product and the limit.
void check_seed_count(int seeds, const std::vector<std::pair<std::size_t, std::string>>& factors);

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
// Output paths (files and folders): trailing slashes dropped, "walk/" is the folder "walk".
extern const CLI::Validator output_path;

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

}  // namespace bvc3d::cli

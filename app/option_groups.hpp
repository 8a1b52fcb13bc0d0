#pragma once
// The option groups every command builds its options from, each added by one call with its help
// written once here: the world (--world, --tilt, --lean, --missing-models), the sensor (--sensor),
// the model (--model or --models), navigation's policy (--policy), parallelism (--jobs), figures
// (--no-figures) and outputs (--out and its kin, with --force and the one rule for outputs that
// exist). Help texts list what is accepted from the library's own lists (world presets, sensor
// presets and LiDAR models, model presets, navigation policies).
// Options made from a parameter table are in table_options.hpp.
// Takes: a command (CLI::App). Gives: its options, their values checked, and what they name built.
#include <CLI/CLI.hpp>

#include <deque>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d::cli {

// ---------------------------------------------------------------------------------------------
// World: --world, --tilt, --lean, --missing-models.

struct WorldOptions {
    std::string world;  // empty until given
    std::optional<double> tilt;
    std::optional<std::string> lean, missing_models;

    // Adds the four options to `cmd`. `role` opens the --world help ("Instead of a recording: ");
    // `fallback` is the world used when --world is not given (shown as its default; "" for none).
    // Returns them (--world first), e.g. for CLI::Option::excludes.
    std::vector<CLI::Option*> add_to(CLI::App& cmd, const std::string& role = "",
                                     const std::string& fallback = "cross");
    // Whether any of the four was given.
    bool given() const;
    // `base` (a trial YAML's world) with what was given: --world replaces it whole, with tilt, lean
    // and missing models at their defaults unless given; the others replace their part.
    WorldSpec over(WorldSpec base) const;
    // The world given, or the fallback; InputError when there is neither.
    WorldSpec spec() const;
    // spec() built, with a warning on standard error naming the models a Gazebo file's world left out.
    WorldDescription resolve() const;

private:
    std::string fallback_ = "cross";
};

// "bvc3d: warning: N included models were not found and are left out (first: NAME)" when any were.
void warn_left_out(const WorldDescription& world);

// ---------------------------------------------------------------------------------------------
// Sensor: --sensor.

// Adds --sensor (a sensor preset, a LiDAR model or a sensor YAML file, all named in its help from the
// library's list) to `cmd`, bound to `sensor`; `role` opens the help ("With --world: "). A non-empty
// `sensor` shows as the default.
CLI::Option* add_sensor_option(CLI::App& cmd, std::string& sensor, const std::string& role = "");

// ---------------------------------------------------------------------------------------------
// Model: --model (one) or a comma-separated list.

enum class ModelCount { one, list };
// Adds `flag` ("--model" or "--models") naming one model or a comma-separated list: presets (named in
// the help from model_presets()) or model YAML files. A non-empty `model` shows as the default.
CLI::Option* add_model_option(CLI::App& cmd, std::string& model, ModelCount count, const std::string& flag = "--model",
                              const std::string& role = "");
// The items of a --model list, or InputError "FLAG lists no model".
std::vector<std::string> model_list(const std::string& text, const std::string& flag = "--model");

// ---------------------------------------------------------------------------------------------
// Navigation policy: --policy.

// Adds --policy (the controller of navigation's starts, named in its help from the library's list,
// config/policy_kinds.hpp) to `cmd`, bound to `policy` (shown as the default).
CLI::Option* add_policy_option(CLI::App& cmd, std::string& policy);

// ---------------------------------------------------------------------------------------------
// Parallelism: --jobs (and --threads, a hidden alias).

inline constexpr int max_jobs = 4096;  // values above are refused
// Adds --jobs to `cmd`: "`what` in parallel; 0 (the default): one per core" and `note`.
CLI::Option* add_jobs_option(CLI::App& cmd, int& jobs, const std::string& what, const std::string& note = "");
// --jobs 0 .. max_jobs, or InputError naming --jobs.
void check_jobs(int jobs);

// ---------------------------------------------------------------------------------------------
// Figures: --no-figures (and --no-figure, --no-report: hidden aliases, the names of earlier versions).

// Adds --no-figures ("Skip `what`: the tables are written all the same") to `cmd`.
CLI::Option* add_no_figures_option(CLI::App& cmd, bool& no_figures, const std::string& what = "the figures");

// ---------------------------------------------------------------------------------------------
// Outputs: --out (and --csv, --cells, --export), --force and the rule for outputs that exist
// (docs/experiments.md#outputs):
// - an output that exists is refused (exit 2, naming it) unless --force: a file, a folder that is not
//   empty, a bag;
// - except where a command resumes its own: a trial file (run, replay) is run again in place (a
//   complete one with the same configuration is left as it is), and a results folder (paper,
//   flight, sweep, navigate) is resumed; a file or folder of another kind there is refused unless
//   --force.
// A file where a folder is expected, or a folder where a file is, is refused even with --force.

enum class OutputKind {
    file,            // one file (a CSV, a map, a model YAML)
    folder,          // a folder of the command's files (tables, a page)
    file_or_folder,  // as the command's format says (export-scans: a bag file or a folder of scans)
    trial_file,      // run, replay: resumed or run again in place
    results_folder,  // paper, flight, sweep, navigate: resumed in place
};

class Outputs {
public:
    Outputs() = default;
    Outputs(const Outputs&) = delete;  // the options hold the addresses of the paths
    Outputs& operator=(const Outputs&) = delete;

    // Adds `flag` to `cmd` for the output `path` (trailing slashes dropped; a non-empty `path` shows
    // as the default), its help ending with what becomes of an existing one; the first call also adds
    // --force. A results folder is the command's own when it holds one of `own` (names; "*.h5" for
    // any name ending in .h5).
    CLI::Option* add(CLI::App& cmd, const std::string& flag, std::string& path, OutputKind kind,
                     const std::string& help, std::vector<std::string> own = {});
    // Every output given ("-", standard output, aside) checked against the rule: InputError naming
    // the flag and the path when it refuses one.
    void check() const;
    bool force = false;

private:
    struct Entry {
        std::string flag;
        std::string* path;
        OutputKind kind;
        std::vector<std::string> own;
    };
    std::deque<Entry> entries_;
};

// The rule for one output (what Outputs::check applies to each); `own` as in Outputs::add.
void check_output(const std::string& flag, const std::filesystem::path& path, OutputKind kind, bool force,
                  const std::vector<std::string>& own = {});

// What a results folder of the experiment engine holds (paper, flight, sweep).
const std::vector<std::string>& experiment_folder_marks();

}  // namespace bvc3d::cli

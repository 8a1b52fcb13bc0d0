#include "option_groups.hpp"

#include <iostream>
#include <type_traits>

#include "bvc3d/config/building.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/config/policy_kinds.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/output_lock.hpp"
#include "bvc3d/recorder/trial_file.hpp"
#include "bvc3d/sensor/lidar_models.hpp"
#include "cli_common.hpp"

namespace bvc3d::cli {

namespace fs = std::filesystem;

namespace {

std::string joined(const std::vector<std::string>& items, const std::string& separator = ", ") {
    std::string out;
    for (const auto& s : items) out += (out.empty() ? "" : separator) + s;
    return out;
}

// A hidden option: an earlier version's name, still read, no longer shown.
template <class T>
void add_hidden_alias(CLI::App& cmd, const std::string& name, T& value) {
    if constexpr (std::is_same_v<T, bool>) cmd.add_flag(name, value)->group("");
    else cmd.add_option(name, value)->group("");
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// World

std::vector<CLI::Option*> WorldOptions::add_to(CLI::App& cmd, const std::string& role, const std::string& fallback) {
    fallback_ = fallback;
    std::string presets;
    for (const auto& p : config::world_preset_names()) presets += (presets.empty() ? "" : ", ") + p;
    auto* w = cmd.add_option("--world", world,
                             role + "World: a preset (" + presets +
                                 "), a world YAML file or a Gazebo world file (.world, .sdf; docs/buildings.md)" +
                                 (fallback.empty() ? "" : " [" + fallback + "]"));
    auto* t = cmd.add_option("--tilt", tilt,
                             "Degrees the central walls of the cross arena lean (the presets cross and cross-webots; "
                             "0 unless given)");
    auto* l = cmd.add_option("--lean", lean,
                             "The corner the cross arena's central walls lean toward: " + joined(cross_arena_leans()) +
                                 " [" + cross_arena_leans().front() + "]");
    const auto& missing = config::missing_models_names();
    auto* m = cmd.add_option("--missing-models", missing_models,
                             "A Gazebo world file's included models that are not on the model path: '" + missing[1] +
                                 "' builds the world without them (a warning names them), '" + missing[0] +
                                 "' refuses the world [" + missing[0] + "]");
    return {w, t, l, m};
}

bool WorldOptions::given() const { return !world.empty() || tilt || lean || missing_models; }

WorldSpec WorldOptions::over(WorldSpec base) const {
    if (!world.empty()) base = WorldSpec{world, std::nullopt, "+x+y"};
    if (tilt) base.tilt_deg = tilt;
    if (lean) base.lean = *lean;
    if (missing_models) try {
            base.missing_models = config::parse_missing_models(*missing_models);
        } catch (const InputError& e) {
            throw InputError(std::string("--missing-models: ") + e.what());
        }
    return base;
}

WorldSpec WorldOptions::spec() const {
    if (world.empty() && fallback_.empty()) throw InputError("give --world");
    return over(WorldSpec{fallback_, std::nullopt, "+x+y"});
}

WorldDescription WorldOptions::resolve() const {
    WorldDescription w = spec().resolve();
    warn_left_out(w);
    return w;
}

void warn_left_out(const WorldDescription& world) {
    if (const auto& out = world.left_out; !out.empty())
        std::cerr << "bvc3d: warning: " << out.size() << " included model" << (out.size() == 1 ? " was" : "s were")
                  << " not found and " << (out.size() == 1 ? "is" : "are")
                  << " left out (first: " << printable(out.front()) << ")\n";
}

// ---------------------------------------------------------------------------------------------
// Sensor

CLI::Option* add_sensor_option(CLI::App& cmd, std::string& sensor, const std::string& role) {
    std::vector<std::string> scanners, lidars;
    for (const auto& name : config::sensor_preset_names()) (find_lidar_model(name) ? lidars : scanners).push_back(name);
    return cmd.add_option("--sensor", sensor,
                          role + "Sensor: a preset (" + joined(scanners) + "), a LiDAR model (" + joined(lidars) +
                              ") or a sensor YAML file (docs/worlds.md#sensors)" +
                              (sensor.empty() ? "" : " [" + sensor + "]"));
}

// ---------------------------------------------------------------------------------------------
// Model

CLI::Option* add_model_option(CLI::App& cmd, std::string& model, ModelCount count, const std::string& flag,
                              const std::string& role) {
    const std::string presets = joined(model_preset_names());
    const std::string what = count == ModelCount::one
                                 ? "Model: a preset (" + presets + ") or a model YAML file"
                                 : "Models, comma-separated: presets (" + presets + ") or model YAML files";
    return cmd.add_option(flag, model, role + what + " (docs/model.md)" + (model.empty() ? "" : " [" + model + "]"));
}

std::vector<std::string> model_list(const std::string& text, const std::string& flag) {
    auto models = split_commas(text);
    if (models.empty()) throw InputError(flag + " lists no model");
    return models;
}

// ---------------------------------------------------------------------------------------------
// Navigation policy

CLI::Option* add_policy_option(CLI::App& cmd, std::string& policy) {
    return cmd
        .add_option("--policy", policy,
                    "The controller of the starts (docs/navigation.md#policies): " + policy_names_text())
        ->capture_default_str();
}

// ---------------------------------------------------------------------------------------------
// Parallelism

CLI::Option* add_jobs_option(CLI::App& cmd, int& jobs, const std::string& what, const std::string& note) {
    auto* option = cmd.add_option("--jobs", jobs, what + " in parallel; 0 (the default): one per core" + note);
    add_hidden_alias(cmd, "--threads", jobs);
    return option;
}

void check_jobs(int jobs) {
    if (jobs < 0) throw InputError("--jobs must be >= 0 (0: one per core), got " + std::to_string(jobs));
    if (jobs > max_jobs)
        throw InputError("--jobs " + std::to_string(jobs) + " is more than the limit of " + std::to_string(max_jobs));
}

// ---------------------------------------------------------------------------------------------
// Figures

CLI::Option* add_no_figures_option(CLI::App& cmd, bool& no_figures, const std::string& what) {
    auto* option = cmd.add_flag("--no-figures", no_figures, "Skip " + what + " (the tables are written all the same)");
    add_hidden_alias(cmd, "--no-figure", no_figures);
    add_hidden_alias(cmd, "--no-report", no_figures);
    return option;
}

// ---------------------------------------------------------------------------------------------
// Outputs

namespace {

// What the help of an output says becomes of an existing one.
std::string rule_text(OutputKind kind) {
    switch (kind) {
        case OutputKind::file:
            return "an existing file is refused unless --force";
        case OutputKind::folder:
            return "an existing folder that is not empty is refused unless --force";
        case OutputKind::file_or_folder:
            return "an existing one is refused unless --force";
        case OutputKind::trial_file:
            return "its own trial file is resumed or run again in place; any other file is refused unless --force";
        case OutputKind::results_folder:
            return "a rerun resumes its own results there; a folder holding other files is refused unless --force";
    }
    return "";
}

bool matches(const std::string& name, const std::string& pattern) {
    if (pattern.size() > 1 && pattern[0] == '*')
        return name.size() >= pattern.size() - 1 && name.ends_with(pattern.substr(1));
    return name == pattern;
}

// The first entry of `folder` (in name order) other than the lock file, or "" when there is none.
std::string first_entry(const fs::path& folder) {
    std::string first;
    for (const auto& e : fs::directory_iterator(folder)) {
        const std::string name = e.path().filename().string();
        if (e.path() == folder_lock_path(folder) || name == ".bvc3d.lock") continue;
        if (first.empty() || name < first) first = name;
    }
    return first;
}

}  // namespace

const std::vector<std::string>& experiment_folder_marks() {
    static const std::vector<std::string> marks{"*.h5", ".checkpoints", "trials.csv", "sweep.yaml"};
    return marks;
}

void check_output(const std::string& flag, const fs::path& given, OutputKind kind, bool force,
                  const std::vector<std::string>& own) {
    if (given.empty() || given == "-") return;
    const fs::path path = without_trailing_slash(given);
    const std::string named = flag + " '" + path.string() + "'";
    std::error_code ec;
    const auto status = fs::status(path, ec);
    if (!fs::exists(status)) return;
    const bool folder = fs::is_directory(status);
    const bool wants_folder = kind == OutputKind::folder || kind == OutputKind::results_folder;
    const bool wants_file = kind == OutputKind::file || kind == OutputKind::trial_file;
    if (wants_folder && !folder) throw InputError(named + " exists and is not a folder");
    if (wants_file && folder) throw InputError(named + " is a folder, not a file");
    if (folder) {
        const std::string first = first_entry(path);
        if (first.empty()) return;  // an empty folder is new
        if (kind == OutputKind::results_folder)
            for (const auto& e : fs::directory_iterator(path))
                for (const auto& mark : own)
                    if (matches(e.path().filename().string(), mark)) return;  // its own: resumed
        if (force) return;
        throw InputError(named +
                         (kind == OutputKind::results_folder ? " holds files of another kind (first: '"
                                                             : " exists and holds files (first: '") +
                         first + "'): give another " + flag + ", or --force to write into it");
    }
    if (kind == OutputKind::trial_file && is_trial_file(path)) return;  // its own: run again or left as it is
    if (force) return;
    throw InputError(named + (kind == OutputKind::trial_file ? " exists and is not a trial file" : " exists") +
                     ": give another " + flag + ", or --force to replace it");
}

CLI::Option* Outputs::add(CLI::App& cmd, const std::string& flag, std::string& path, OutputKind kind,
                          const std::string& help, std::vector<std::string> own) {
    if (entries_.empty())
        cmd.add_flag("--force", force,
                     "Write over outputs that exist instead of stopping: a file is replaced, a folder written into "
                     "(docs/experiments.md#outputs-that-exist)");
    entries_.push_back({flag, &path, kind, std::move(own)});
    auto* option = cmd.add_option(flag, path, help + " (" + rule_text(kind) + ")")->transform(output_path);
    return path.empty() ? option : option->capture_default_str();
}

void Outputs::check() const {
    for (const auto& e : entries_) check_output(e.flag, *e.path, e.kind, force, e.own);
}

}  // namespace bvc3d::cli

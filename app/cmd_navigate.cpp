// bvc3d navigate: navigation to goals (docs/navigation.md), options plus the experiment engine: one navigation trial
// per model and seed (config/navigation_spec.hpp), run into trial files in the output folder as every experiment's
// trials are (checkpointed, resumed, memory-checked, --jobs at once), then the navigation tables (report stage:
// starts.csv, learning.csv, paths.csv, reward_map.csv, summary.csv/.md) and figures from those files.
#include <algorithm>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/navigation_spec.hpp"
#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/config/yaml_reader.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/experiment/navigation.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "option_groups.hpp"
#include "python_module.hpp"
#include "run_options.hpp"
#include "table_options.hpp"

namespace bvc3d::cli {

namespace {

struct NavigateOptions {
    std::string config, goals, model = "2d", policy = default_policy_kind().name;
    WorldOptions world;
    int seeds = 1;
    std::uint64_t first_seed = 0;
    TableOptions<NavigationParams> nav{NavigationParams::table()};
    bool dry_run = false;
    RunOptions run;  // --out (with --force), --jobs, --checkpoint-minutes, --no-memory-check, --no-figures
};

// What one command runs: models × seeds in a world with its goals, and every parameter.
struct NavigatePlan {
    std::string world, lean = "+x+y";
    std::optional<double> tilt;
    config::MissingModels missing_models = config::MissingModels::error;
    std::vector<NavigationGoal> goals;
    std::vector<std::string> models;  // as given: a preset name or a model file
    int seeds = 1;
    std::uint64_t first_seed = 0;
    NavigationParams nav;
    AdjacencyParams adjacency;
    RewardParams reward;
    FlightParams flight;
    std::shared_ptr<const PolicySpec> policy = default_policy();
};

// A goal of 2 numbers (on the floor) or 3 (in the air, the flying agent); else nothing.
std::optional<NavigationGoal> goal_of(const std::vector<double>& v) {
    if (v.size() == 2) return NavigationGoal(v[0], v[1]);
    if (v.size() == 3) return NavigationGoal(v[0], v[1], v[2]);
    return std::nullopt;
}

// "x,y;x,y" or "x,y,z;x,y,z": the goals (InputError naming the bad one).
std::vector<NavigationGoal> parse_goals(const std::string& text) {
    std::vector<NavigationGoal> out;
    std::stringstream all(text);
    std::string item;
    while (std::getline(all, item, ';')) {
        if (item.find_first_not_of(" \t") == std::string::npos) continue;
        std::vector<double> v;
        std::stringstream numbers(item);
        for (std::string n; std::getline(numbers, n, ',');) v.push_back(parse_number(n, "--goals"));
        const auto goal = goal_of(v);
        if (!goal || item.back() == ',')
            throw InputError("--goals: '" + item + "' is not x,y or x,y,z (give goals as x,y;x,y or x,y,z;x,y,z)");
        out.push_back(*goal);
    }
    return out;
}

NavigatePlan plan_of_options(const NavigateOptions& o) {
    if (o.world.world.empty()) throw InputError("navigate: give --world and --goals, or --config");
    if (o.seeds < 1) throw InputError("--seeds: must be at least 1");
    NavigatePlan p;
    const WorldSpec world = o.world.spec();
    p.world = world.source, p.tilt = world.tilt_deg, p.lean = world.lean, p.missing_models = world.missing_models;
    p.goals = parse_goals(o.goals);
    p.models = model_list(o.model);
    p.seeds = o.seeds, p.first_seed = o.first_seed;
    o.nav.apply(p.nav);
    p.nav.validate();
    p.policy = config::policy_named(o.policy);
    return p;
}

// The sweep-friendly YAML (docs/navigation.md#a-yaml-file): world (a preset or a file, relative to the YAML's
// folder), tilt, lean, missing_models, goals ([[x, y], ...]), models (a name or a list), seeds, first_seed, the
// parameter tables navigation:, adjacency:, reward:, flight:, and policy: with its parameters' section
// (config/policy_kinds.hpp). Any other key: InputError naming it.
NavigatePlan plan_of_yaml(const std::string& file) {
    const auto v = config::YamlView::load_file(file);
    std::vector<std::string> keys{"world", "tilt",       "lean",       "missing_models", "goals",  "models",
                                  "seeds", "first_seed", "navigation", "adjacency",      "reward", "flight"};
    for (const auto& key : config::policy_yaml_keys()) keys.push_back(key);
    v.expect_map(keys);
    NavigatePlan p;
    p.world = config::path_in_file(v, v["world"].as_string());
    if (v.has("tilt")) p.tilt = v["tilt"].as_double();
    p.lean = v.get("lean", p.lean);
    if (v.has("missing_models")) try {
            p.missing_models = config::parse_missing_models(v["missing_models"].as_string());
        } catch (const ConfigError&) {
            throw;
        } catch (const InputError& e) {
            v["missing_models"].fail(e.what());
        }
    const auto goals = v["goals"];
    if (!goals.is_sequence()) goals.fail("must be a list of [x, y] or of [x, y, z]");
    for (std::size_t i = 0; i < goals.size(); ++i) {
        const auto goal = goal_of(goals.at(i).as_doubles());
        if (!goal) goals.at(i).fail("must be [x, y] (on the floor) or [x, y, z] (flying)");
        p.goals.push_back(*goal);
    }
    if (v.has("models")) {
        const auto m = v["models"];
        if (m.is_scalar()) {
            p.models.push_back(m.as_string());
        } else {
            if (m.size() == 0) m.fail("must name at least one model");
            for (std::size_t i = 0; i < m.size(); ++i) p.models.push_back(m.at(i).as_string());
        }
    } else {
        p.models = {"2d"};
    }
    for (std::string& m : p.models) m = config::path_in_file(v, m);
    p.seeds = v.get("seeds", 1);
    if (p.seeds < 1) v["seeds"].fail("must be at least 1");
    if (v.has("first_seed")) p.first_seed = v["first_seed"].as_uint64();
    if (v.has("navigation")) config::read_table(v["navigation"], p.nav, NavigationParams::table());
    if (v.has("adjacency")) config::read_table(v["adjacency"], p.adjacency, AdjacencyParams::table());
    if (v.has("reward")) config::read_table(v["reward"], p.reward, RewardParams::table());
    if (v.has("flight")) config::read_table(v["flight"], p.flight, FlightParams::table());
    p.policy = config::policy_from_yaml(v);
    return p;
}

// A world or model file by its stem (configs/worlds/nav-open.yaml: nav-open), a preset by its name.
std::string label_of(const std::string& name_or_file) {
    const std::filesystem::path path(name_or_file);
    return std::filesystem::is_regular_file(path) ? path.stem().string() : name_or_file;
}

void navigate_command(const NavigateOptions& o) {
    o.run.check();
    const NavigatePlan plan = o.config.empty() ? plan_of_options(o) : plan_of_yaml(o.config);
    auto nav = std::make_shared<NavigationSpec>();
    nav->space.goals = plan.goals;
    nav->space.nav = plan.nav;
    nav->space.flight = plan.flight;
    nav->space.n_hd = plan.adjacency.n_hd;
    nav->adjacency = plan.adjacency;
    nav->reward = plan.reward;
    nav->policy = plan.policy;
    const std::string world_name = label_of(plan.world) + (plan.tilt ? "-" + format_number(*plan.tilt) : "");
    std::vector<TrialConfig> trials;
    try {  // before anything is written; a YAML file's errors name it
        std::vector<ModelSpec> models;
        for (const auto& m : plan.models) {
            models.push_back(config::resolve_model(m));
            nav->check_model(models.back());
        }
        const WorldSpec world_spec{plan.world, plan.tilt, plan.lean, plan.missing_models};
        const World world(world_spec.resolve());
        warn_left_out(world.description());
        check_goals(world, *nav);
        for (std::size_t m = 0; m < models.size(); ++m)
            for (int k = 0; k < plan.seeds; ++k) {
                TrialConfig t = navigation_trial(world_spec, models[m], nav, plan.first_seed + std::uint64_t(k));
                t.condition = world_name + "_" + label_of(plan.models[m]);
                t.swept = {{"world", world_name}, {"model", plan.models[m]}};
                t.origin = o.config.empty() ? "bvc3d navigate" : o.config;
                trials.push_back(std::move(t));
            }
    } catch (const InputError& e) {
        if (o.config.empty()) throw;
        throw InputError(o.config + ": " + e.what());
    }
    check_folder_holds_one_kind(o.run.out, trials);
    if (o.dry_run) {
        std::printf("%s: %zu goal(s), %zu model(s) × %d seed(s) = %zu learning runs, %d starts per goal each\n",
                    world_name.c_str(), plan.goals.size(), plan.models.size(), plan.seeds, trials.size(),
                    plan.nav.starts);
        return;
    }
    if (o.run.out.empty()) throw InputError("--out: give an output folder");
    run_experiment_in_folder(trials, o.run);
}

}  // namespace

void add_navigate_command(CLI::App& app) {
    auto o = std::make_shared<NavigateOptions>();
    auto* cmd = app.add_subcommand("navigate",
                                   "Navigation to goals: learn by a random walk, then reach each goal "
                                   "from random starts (docs/navigation.md)");
    auto* config = cmd->add_option("--config", o->config,
                                   "A YAML file: world, goals, models, seeds and parameters (docs/navigation.md)");
    std::vector<CLI::Option*> given = o->world.add_to(*cmd, "", "");
    given.push_back(cmd->add_option("--goals", o->goals,
                                    "Goals on the floor, x,y[;x,y...], or in the air for the flying agent, "
                                    "x,y,z[;x,y,z...] (m)"));
    given.push_back(add_model_option(*cmd, o->model, ModelCount::list));
    given.push_back(add_policy_option(*cmd, o->policy));
    given.push_back(cmd->add_option("--seeds", o->seeds, "Learning runs (seeds first-seed, first-seed+1, ...)")
                        ->capture_default_str());
    given.push_back(
        cmd->add_option("--first-seed", o->first_seed, "The first seed")->check(seed_check)->capture_default_str());
    static const NavigationParams defaults;
    for (CLI::Option* g : o->nav.add_to(*cmd, {"starts", "max_learn_hours", "coverage", "goal_visits"}, &defaults))
        given.push_back(g);
    for (CLI::Option* g : given) config->excludes(g);
    cmd->add_flag("--dry-run", o->dry_run, "Read and check everything, say what would run, and exit");
    o->run.add_out(*cmd,
                   "Output folder: a trial file per model and seed, WORLD_MODEL_seedN.h5 (a run started again "
                   "resumes there); the tables starts.csv, paths.csv, learning.csv, reward_map.csv, summary.csv, "
                   "summary.md; the figures paths.png, reward_map.png (goals on the floor) and "
                   "path_ratio_learning.png",
                   OutputKind::results_folder);
    o->run.add_jobs(*cmd, "Learning runs", " (the files are the same)");
    o->run.add_checkpoint_minutes(*cmd);
    o->run.add_no_memory_check(*cmd);
    o->run.add_no_figures(*cmd);
    cmd->callback([o] { navigate_command(*o); });
}

}  // namespace bvc3d::cli

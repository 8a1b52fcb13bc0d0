#include "bvc3d/config/trial_yaml.hpp"

#include <algorithm>
#include <filesystem>

#include "bvc3d/config/agent_kinds.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/navigation_spec.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d::config {

namespace {

WorldSpec world_from(const YamlView& v) {
    WorldSpec w;
    if (v.is_scalar()) {
        w.source = path_in_file(v, v.as_string());
    } else {
        v.expect_map({"source", "tilt_deg", "lean", "missing_models"});
        w.source = path_in_file(v, v.get("source", w.source));
        if (v.has("tilt_deg")) w.tilt_deg = v["tilt_deg"].as_double();
        w.lean = v.get("lean", w.lean);
        if (v.has("missing_models")) try {
                w.missing_models = parse_missing_models(v["missing_models"].as_string());
            } catch (const ConfigError&) {
                throw;
            } catch (const InputError& e) {
                v["missing_models"].fail(e.what());
            }
    }
    try {
        w.resolve();  // check now, with the key in the message
    } catch (const ConfigError&) {
        throw;
    } catch (const InputError& e) {
        v.fail(e.what());
    }
    return w;
}

ModelSpec model_from(const YamlView& v) {
    if (!v.is_scalar()) return model_from_yaml(v);
    const std::string name = v.as_string();
    try {
        return resolve_model(path_in_file(v, name));
    } catch (const ConfigError&) {
        throw;
    } catch (const InputError& e) {
        v.fail(e.what());
    }
}

// extent: data (the trajectory's bounds), arena (the walkable region's) or [xmin, xmax, ymin, ymax].
void analysis_from(const YamlView& v, TrialConfig& t) {
    read_table(v, t.analysis, analysis::AnalysisParams::table(), {"extent"});
    if (!v.has("extent")) return;
    const YamlView e = v["extent"];
    if (e.is_sequence()) {
        const auto b = e.as_doubles(4);
        t.analysis.extent = analysis::Extent{b[0], b[1], b[2], b[3]};
        try {
            t.analysis.extent->validate();
        } catch (const InputError& err) {
            e.fail(err.what());
        }
        t.arena_extent = false;
        return;
    }
    const std::string extent = e.as_string();
    if (extent != "data" && extent != "arena")
        e.fail("must be data, arena or [xmin, xmax, ymin, ymax], got '" + extent + "'");
    t.arena_extent = extent == "arena";
}

// `navigation:` (docs/navigation.md#as-a-trial): goals ([[x, y], ...] or [[x, y, z], ...]), the navigation table's
// keys, adjacency: and reward: tables, and policy: with its parameters' section; the bodies from the trial's robot:
// or flight: section.
std::shared_ptr<NavigationSpec> navigation_from(const YamlView& v, const YamlView& trial) {
    auto nav = std::make_shared<NavigationSpec>();
    std::vector<std::string> also{"goals", "adjacency", "reward"};
    for (const auto& key : policy_yaml_keys()) also.push_back(key);
    read_table(v, nav->space.nav, NavigationParams::table(), also);
    if (!v.has("goals")) v.fail("needs goals: a list of [x, y] (on the floor) or [x, y, z] (flying)");
    const YamlView goals = v["goals"];
    if (!goals.is_sequence() || goals.size() == 0) goals.fail("must be a list of [x, y] or of [x, y, z]");
    for (std::size_t i = 0; i < goals.size(); ++i) {
        const auto g = goals.at(i).as_doubles();
        if (g.size() == 2) nav->space.goals.emplace_back(g[0], g[1]);
        else if (g.size() == 3) nav->space.goals.emplace_back(g[0], g[1], g[2]);
        else goals.at(i).fail("must be [x, y] (on the floor) or [x, y, z] (flying)");
    }
    if (v.has("adjacency")) read_table(v["adjacency"], nav->adjacency, AdjacencyParams::table());
    if (v.has("reward")) read_table(v["reward"], nav->reward, RewardParams::table());
    nav->policy = policy_from_yaml(v);
    if (trial.has("robot")) read_table(trial["robot"], nav->space.robot, RobotParams::table());
    if (trial.has("flight")) read_table(trial["flight"], nav->space.flight, FlightParams::table());
    nav->space.n_hd = nav->adjacency.n_hd;
    check_at(v, [&] { nav->validate(); });
    return nav;
}

}  // namespace

std::vector<std::string> trial_keys() {
    std::vector<std::string> keys{"world", "model", "seed", "protocol", "navigation", "analysis"};
    const auto agents = agent_yaml_keys();
    keys.insert(keys.end() - 1, agents.begin(), agents.end());
    return keys;
}

TrialConfig trial_from_yaml(const YamlView& v) {
    v.expect_map(trial_keys());
    TrialConfig t;
    if (v.has("world")) t.world = world_from(v["world"]);
    if (v.has("model")) t.model = model_from(v["model"]);
    if (v.has("seed")) t.seed = v["seed"].as_uint64();
    if (v.has("protocol")) read_table(v["protocol"], t.protocol, Protocol::table());
    t.set_agent(agent_from_yaml(v));
    if (v.has("analysis")) analysis_from(v["analysis"], t);
    if (v.has("navigation")) {
        if (v.has("protocol"))
            v["protocol"].fail(
                "a navigation trial learns until its criteria or navigation.max_learn_hours, then runs "
                "its episodes: it takes no protocol");
        if (v.has("trajectory")) v["trajectory"].fail("a navigation trial walks on its own: it takes no trajectory");
        const auto nav = navigation_from(v["navigation"], v);
        check_at(v["navigation"], [&] {
            TrialConfig n = navigation_trial(t.world, t.model, nav, t.seed);
            n.analysis = t.analysis;
            n.arena_extent = t.arena_extent;
            t = std::move(n);
        });
    }
    t.origin = v.file();
    // What the sections allow one by one may still not fit together (too short a protocol for
    // two samples, too many weights): reported at the key the check names.
    try {
        t.validate();
    } catch (const params::ParamError& e) {
        std::vector<std::string> sections{"protocol"};
        for (const auto& agent : agent_yaml_keys()) sections.push_back(agent);
        sections.push_back("analysis");
        for (const auto& section : sections)
            if (v.has(section) && v[section].is_map() && v[section].has(e.key())) v[section][e.key()].fail(e.reason());
        v.fail(e.what());
    } catch (const InputError& e) {  // a model and an agent that do not go together: name the file
        if (dynamic_cast<const ConfigError*>(&e)) throw;
        v.fail(e.what());
    }
    return t;
}

TrialConfig load_trial_file(const std::string& path) { return trial_from_yaml(YamlView::load_file(path)); }

namespace {

std::string list(const std::vector<std::string>& names) {
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
}

// A path as written into generated YAML: absolute, so that the text means the same file wherever it is saved.
std::string file_text(const std::string& path) {
    return params::CommentedYaml::scalar(std::filesystem::absolute(path).lexically_normal().string());
}

}  // namespace

std::string trial_to_commented_yaml(const TrialConfig& t) {
    params::CommentedYaml out;
    out.comment("", "A trial (docs/experiments.md): every key. `bvc3d run --config FILE` runs it.");
    const auto presets = world_preset_names();
    const bool preset_world = std::find(presets.begin(), presets.end(), t.world.source) != presets.end();
    out.section("", "world");
    out.line("  ", "source", preset_world ? t.world.source : file_text(t.world.source),
             "a world preset (" + list(presets) + "), a world YAML file or a Gazebo world (.world, .sdf)");
    if (world_preset_takes_tilt(t.world.source) || t.world.tilt_deg)
        out.line("  ", "tilt_deg", format_number(t.world.tilt_deg.value_or(0.0)),
                 "cross and cross-webots only: degrees the central walls lean");
    if (preset_world && t.world.source.rfind("cross", 0) == 0)
        out.line("  ", "lean", params::CommentedYaml::scalar(t.world.lean), "the corner they lean toward");
    if (t.world.missing_models != MissingModels::error)
        out.line("  ", "missing_models", missing_models_names()[static_cast<std::size_t>(t.world.missing_models)],
                 "a Gazebo world file's models that are not found: error or skip (left out)");
    if (const std::string preset = preset_name_of(t.model); !preset.empty()) {
        out.line("", "model", preset,
                 "a preset (" + list(model_preset_names()) +
                     "), a model YAML file or a mapping (bvc3d config --model NAME)");
    } else {
        out.section("", "model", "a model mapping (docs/model.md#custom-models-yaml)");
        write_model(out, t.model, "  ");
    }
    out.line("", "seed", std::to_string(t.seed), "seeds the walk, the weights and the sensor noise");
    out.section("", "protocol");
    out.fields(Protocol::table(), t.protocol, "  ");
    t.agent->write_yaml(out);
    out.section("", "analysis");
    out.fields(analysis::AnalysisParams::table(), t.analysis, "  ");
    out.line("  ", "extent", t.arena_extent ? "arena" : "data",
             "rate-map grid over the trajectory's bounds (data) or the walkable region's (arena)");
    return out.str();
}

}  // namespace bvc3d::config

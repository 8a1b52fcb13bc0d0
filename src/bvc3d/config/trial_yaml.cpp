#include "bvc3d/config/trial_yaml.hpp"

#include <filesystem>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/config/world_yaml.hpp"

namespace bvc3d::config {

namespace {

// A path inside a YAML file is relative to that file (preset names are left alone).
std::string relative_to(const YamlView& v, const std::string& s) {
    if (std::filesystem::path(s).is_absolute()) return s;
    const auto candidate = std::filesystem::path(v.directory()) / s;
    std::error_code ec;
    return std::filesystem::exists(candidate, ec) ? candidate.string() : s;
}

WorldSpec world_from(const YamlView& v) {
    WorldSpec w;
    if (v.is_scalar()) {
        w.source = relative_to(v, v.as_string());
    } else {
        v.expect_map({"source", "tilt_deg", "lean"});
        w.source = relative_to(v, v.get("source", w.source));
        if (v.has("tilt_deg")) w.tilt_deg = v["tilt_deg"].as_double();
        w.lean = v.get("lean", w.lean);
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
        return resolve_model(relative_to(v, name));
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
    if (extent != "data" && extent != "arena") e.fail("must be data, arena or [xmin, xmax, ymin, ymax], got '" + extent + "'");
    t.arena_extent = extent == "arena";
}

std::shared_ptr<const AgentSpec> agent_from(const YamlView& v) {
    if (v.has("robot") && v.has("trajectory"))
        v.fail("give 'robot' (the random walk's robot) or 'trajectory' (a given path), not both");
    if (v.has("trajectory")) {
        const YamlView file = v["trajectory"];
        try {
            return std::make_shared<TrajectorySpec>(TrajectorySpec::from_file(relative_to(file, file.as_string())));
        } catch (const ConfigError&) {
            throw;
        } catch (const InputError& e) {
            file.fail(e.what());
        }
    }
    RobotParams robot;
    if (v.has("robot")) read_table(v["robot"], robot, RobotParams::table());
    return std::make_shared<RandomWalkSpec>(robot);
}

}  // namespace

std::vector<std::string> trial_keys() {
    return {"world", "model", "seed", "protocol", "robot", "trajectory", "analysis"};
}

TrialConfig trial_from_yaml(const YamlView& v) {
    v.expect_map(trial_keys());
    TrialConfig t;
    if (v.has("world")) t.world = world_from(v["world"]);
    if (v.has("model")) t.model = model_from(v["model"]);
    if (v.has("seed")) t.seed = v["seed"].as_uint64();
    if (v.has("protocol")) read_table(v["protocol"], t.protocol, Protocol::table());
    t.agent = agent_from(v);
    if (v.has("analysis")) analysis_from(v["analysis"], t);
    t.origin = v.file();
    // What the sections allow one by one may still not fit together (too short a protocol for
    // two samples, too many weights): reported at the key the check names.
    try {
        t.validate();
    } catch (const params::ParamError& e) {
        for (const char* section : {"protocol", "robot", "analysis"})
            if (v.has(section) && v[section].is_map() && v[section].has(e.key())) v[section][e.key()].fail(e.reason());
        v.fail(e.what());
    }
    return t;
}

TrialConfig load_trial_file(const std::string& path) { return trial_from_yaml(YamlView::load_file(path)); }

}  // namespace bvc3d::config

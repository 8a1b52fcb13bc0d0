#include "bvc3d/config/trial_yaml.hpp"

#include <filesystem>

#include "bvc3d/config/model_yaml.hpp"
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

Protocol protocol_from(const YamlView& v) {
    Protocol p;
    read_fields(v,
                {{"explore_hours", &p.explore_hours}, {"sample_hours", &p.sample_hours}, {"record_bvc", &p.record_bvc}},
                {"kind"});
    if (v.has("kind")) {
        try {
            p.kind = parse_protocol(v["kind"].as_string());
        } catch (const InputError& e) {
            v["kind"].fail(e.what());
        }
    }
    require_range(v, "explore_hours", p.explore_hours, 0.0, 1e6);
    if (!(p.sample_hours > 0)) v.fail_key("sample_hours", "must be > 0");
    return p;
}

RobotParams robot_from(const YamlView& v) {
    RobotParams r;
    read_fields(v, {{"radius", &r.radius},
                    {"height", &r.height},
                    {"speed", &r.speed},
                    {"turn_rate", &r.turn_rate},
                    {"model_dt", &r.model_dt},
                    {"n_walk", &r.n_walk},
                    {"turn_sd", &r.turn_sd},
                    {"min_update_move", &r.min_update_move}});
    for (const char* k : {"radius", "height", "speed", "turn_rate", "model_dt"})
        if (v.has(k)) require_positive(v, k, v[k].as_double());
    if (r.n_walk < 1) v["n_walk"].fail("must be >= 1");
    require_range(v, "turn_sd", r.turn_sd, 0.0, 100.0);
    require_range(v, "min_update_move", r.min_update_move, 0.0, 1.0);
    return r;
}

void analysis_from(const YamlView& v, TrialConfig& t) {
    auto& a = t.analysis;
    std::string extent = "data", templates = analysis::decoding_templates_name(a.decoding_templates);
    read_fields(v, {{"gridsize", &a.gridsize},
                    {"quantile", &a.quantile},
                    {"eps", &a.dbscan.eps},
                    {"min_samples", &a.dbscan.min_samples},
                    {"d_th", &a.d_th},
                    {"extent", &extent},
                    {"decoding_templates", &templates}});
    try {
        a.decoding_templates = analysis::parse_decoding_templates(templates);
    } catch (const InputError& e) {
        v["decoding_templates"].fail(e.what());
    }
    if (extent != "data" && extent != "arena") v["extent"].fail("must be 'data' or 'arena'");
    t.arena_extent = extent == "arena";
    if (a.gridsize < 2) v["gridsize"].fail("must be >= 2");
    require_range(v, "quantile", a.quantile, 0.0, 1.0);
    require_positive(v, "eps", a.dbscan.eps);
    if (a.dbscan.min_samples < 1) v["min_samples"].fail("must be >= 1");
    require_range(v, "d_th", a.d_th, 0.0, 1e6);
}

}  // namespace

std::vector<std::string> trial_keys() { return {"world", "model", "seed", "protocol", "robot", "analysis"}; }

TrialConfig trial_from_yaml(const YamlView& v) {
    v.expect_map(trial_keys());
    TrialConfig t;
    if (v.has("world")) t.world = world_from(v["world"]);
    t.model = v.has("model") ? model_from(v["model"]) : model_preset("3d-0.2");
    if (v.has("seed")) {
        const long long s = v["seed"].as_int();
        if (s < 0) v["seed"].fail("must be >= 0");
        t.seed = static_cast<std::uint64_t>(s);
    }
    if (v.has("protocol")) t.protocol = protocol_from(v["protocol"]);
    if (v.has("robot")) t.robot = robot_from(v["robot"]);
    if (v.has("analysis")) analysis_from(v["analysis"], t);
    return t;
}

TrialConfig load_trial_file(const std::string& path) { return trial_from_yaml(YamlView::load_file(path)); }

}  // namespace bvc3d::config

#include "bvc3d/config/trial_config.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/navigation_spec.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/recorder/trial_file.hpp"

namespace bvc3d {

namespace {

std::uint64_t text_hash(const std::string& s) {
    std::uint64_t h = 0x6276633364ull;
    for (unsigned char c : s) h = hash_u64(h, c, 0x9e37);
    return h;
}

}  // namespace

WorldDescription WorldSpec::resolve() const {
    if (is_none()) throw InputError("this trial has no world (its returns are recorded data)");
    if (in_memory) throw InputError("world '" + source + "' was built in code: give its preset or file to rebuild it");
    return config::resolve_world(source, tilt_deg, lean, missing_models);
}

std::string WorldSpec::label() const {
    if (is_none()) return "none";
    if (in_memory) return source;
    if (config::world_preset_takes_tilt(source)) {
        std::string l = source + "-" + format_number(tilt_deg.value_or(0.0));
        return lean == "+x+y" ? l : l + "_" + lean;
    }
    const auto presets = config::world_preset_names();
    if (std::find(presets.begin(), presets.end(), source) != presets.end()) return source;
    return std::filesystem::path(source).stem().string();
}

std::string WorldSpec::fingerprint() const {
    if (is_none()) return "none";
    if (in_memory) return "built in code: " + source;
    const auto presets = config::world_preset_names();
    if (std::find(presets.begin(), presets.end(), source) != presets.end())
        return "preset " + source + " tilt " + format_number(tilt_deg.value_or(0.0)) + " lean " + lean;
    // The world file's text and that of every mesh it loads: editing either makes a new world.
    auto file_hash = [](const std::string& path) {
        std::ifstream in(path, std::ios::binary);
        std::stringstream text;
        text << in.rdbuf();
        return std::to_string(text_hash(text.str()));
    };
    std::string fp = "file " + std::filesystem::path(source).filename().string() + " " + file_hash(source);
    for (const auto& mesh : config::world_file_meshes(source)) fp += " mesh " + file_hash(mesh);
    if (missing_models == config::MissingModels::skip) fp += " missing-models skip";  // absent at the default
    return fp;
}

const params::Table<Protocol>& Protocol::table() {
    using namespace params;
    static const Table<Protocol> t(
        "protocol",
        {choice("kind", &Protocol::kind,
                {{Kind::explore_then_sample, "explore_then_sample"}, {Kind::online, "online"}, {Kind::learn, "learn"}},
                "explore_then_sample (learn, then record frozen), online (record while learning) or learn (learn "
                "until explore_hours or the agent's end, record nothing: navigation's learning)"),
         real("explore_hours", &Protocol::explore_hours, closed(0, max_agent_hours),
              "h of exploration, learning on, not recorded"),
         real("sample_hours", &Protocol::sample_hours, closed(0, max_agent_hours),
              "h recorded (online: the one phase); more than 0 unless the kind is learn"),
         flag("record_bvc", &Protocol::record_bvc, "also record the BVC rates")});
    return t;
}

void Protocol::validate() const {
    table().check(*this);
    if (records() && !(sample_hours > 0))
        table().fail("sample_hours", "must be in (0, " + format_number(max_agent_hours) + "] (0 only for kind learn)");
}

double Protocol::seconds() const {
    switch (kind) {
        case Kind::online:
            return 3600.0 * sample_hours;
        case Kind::learn:
            return 3600.0 * explore_hours;
        default:
            return 3600.0 * (explore_hours + sample_hours);
    }
}

std::string protocol_name(Protocol::Kind k) {
    return k == Protocol::Kind::online ? "online" : k == Protocol::Kind::learn ? "learn" : "explore_then_sample";
}

Protocol::Kind parse_protocol(const std::string& name) {
    if (name == "explore_then_sample" || name == "paper") return Protocol::Kind::explore_then_sample;
    if (name == "online") return Protocol::Kind::online;
    if (name == "learn") return Protocol::Kind::learn;
    throw InputError("protocol '" + name + "' is not one of explore_then_sample, online, learn");
}

void TrialConfig::set_agent(std::shared_ptr<const AgentSpec> a) {
    if (a->dims() != agent->dims()) {  // the analysis defaults follow the positions' dimension
        const auto defaults = analysis::AnalysisParams::defaults(a->dims());
        if (analysis.dbscan.min_samples == analysis::AnalysisParams::defaults(agent->dims()).dbscan.min_samples)
            analysis.dbscan.min_samples = defaults.dbscan.min_samples;
    }
    agent = std::move(a);
}

std::string InitialWeights::key() const {
    std::uint64_t h = 0x77656967;  // "weig"
    for (const float v : values) {
        std::uint32_t bits;
        std::memcpy(&bits, &v, sizeof bits);
        h = hash_u64(h, bits, 0x57);
    }
    std::ostringstream os;
    os << "weights:\n  source: " << std::filesystem::path(source).filename().string() << "\n  shape: [" << n_place
       << ", " << n_bvc << "]\n  hash: " << std::hex << h << "\n";
    return os.str();
}

std::shared_ptr<const InitialWeights> weights_from_trial_file(const std::filesystem::path& path) {
    TrialWeights w = read_trial_weights(path);
    auto out = std::make_shared<InitialWeights>();
    out->source = path.string();
    out->values = std::move(w.values);
    out->n_place = static_cast<int>(w.n_place);
    out->n_bvc = static_cast<int>(w.n_bvc);
    out->model = std::move(w.model);
    out->model_config = std::move(w.model_config);
    return out;
}

namespace {

// The `bvc:` block of a model's canonical text as (key, value) lines, in order.
std::vector<std::pair<std::string, std::string>> bvc_keys(const std::string& model_text) {
    std::vector<std::pair<std::string, std::string>> keys;
    std::istringstream in(model_text);
    bool inside = false;
    for (std::string line; std::getline(in, line);) {
        if (line == "bvc:") {
            inside = true;
        } else if (inside && line.rfind("  ", 0) == 0) {
            const auto colon = line.find(':');
            if (colon != std::string::npos)
                keys.emplace_back(line.substr(2, colon - 2), colon + 2 <= line.size() ? line.substr(colon + 2) : "");
        } else if (inside) {
            break;
        }
    }
    return keys;
}

}  // namespace

std::string weights_model_mismatch(const std::string& trained, const ModelSpec& model) {
    const auto theirs = bvc_keys(trained), ours = bvc_keys(config::model_to_yaml(model));
    if (theirs.empty()) return "";  // not a model's text: nothing to compare
    for (const auto& [key, value] : ours) {
        const std::string& name = key;  // clang 14 cannot capture a structured binding
        const auto it = std::find_if(theirs.begin(), theirs.end(), [&](const auto& kv) { return kv.first == name; });
        const std::string was = it == theirs.end() ? "(absent)" : it->second;
        if (was != value) return "bvc." + key + " is " + was + " in the model that trained them, " + value + " here";
    }
    return "";
}

void TrialConfig::validate() const {
    model.validate();
    protocol.validate();
    agent->validate();
    analysis.validate();
    // A preset made for one way of moving on an agent that moves the other way (custom models, and
    // given paths, are the user's call).
    if (const std::string preset = config::preset_name_of(model); !preset.empty()) {
        const bool flying_model = find_model_preset(preset)->flying;
        const Locomotion moves = agent->locomotion();
        if (flying_model && moves == Locomotion::ground)
            throw InputError("model '" + preset +
                             "' is a preset for flying agents (its scanner sits at the body's "
                             "center and looks down too): the ground robot uses 2d, 3d-0.1, 3d-0.2, 3d-3l or 2d-8beam; "
                             "or fly with it (trial key flight:, --agent flight)");
        if (!flying_model && moves == Locomotion::flying)
            throw InputError("model '" + preset +
                             "' is a preset for the ground robot (its scanner sits on the robot, "
                             "above the floor): flying agents use fly-up, fly-5l or fly-9l (docs/flying.md#models)");
    }
    if (world.is_none() && (!returns || returns->needs_world()))
        throw InputError("a trial without a world needs recorded returns (a replay)");
    if (world.is_none() && arena_extent) throw InputError("a trial without a world has no arena to bin over");
    if (weights && (weights->n_place != model.place.n_place || weights->n_bvc != model.bvc.n_cells() ||
                    weights->values.size() != static_cast<std::size_t>(weights->n_place) * weights->n_bvc))
        throw InputError("weights from '" + weights->source + "' are " + std::to_string(weights->n_place) + " × " +
                         std::to_string(weights->n_bvc) + "; model '" + model.name + "' needs " +
                         std::to_string(model.place.n_place) + " × " + std::to_string(model.bvc.n_cells()));
    if (weights && !weights->model_config.empty())
        if (const std::string why = weights_model_mismatch(weights->model_config, model); !why.empty())
            throw InputError("weights from '" + weights->source + "' were trained by model '" + weights->model +
                             "', whose BVCs are not model '" + model.name + "''s: " + why);
    // Decoding compares two halves of the recorded samples: at least two model steps are needed.
    if (protocol.records() && protocol.sample_hours * 3600.0 * agent->steps_per_second() < 2.0)
        Protocol::table().fail("sample_hours",
                               "= " + format_number(protocol.sample_hours) + " h records fewer than 2 model steps");
}

void TrialConfig::check_runnable() const {
    try {
        validate();
        if (!world.is_none()) agent->check_world(world.resolve());  // a replay has no world
    } catch (const InputError& e) {
        // Name the file the trial came from, unless the message already names a file of its own.
        const std::string what = e.what();
        if (origin.empty() || what.find(origin) != std::string::npos || dynamic_cast<const ConfigError*>(&e)) throw;
        throw InputError(origin + ": " + what);
    }
}

void check_runnable(const std::vector<TrialConfig>& trials) {
    std::set<std::string> seen;
    for (const auto& t : trials) {
        t.validate();
        if (seen.insert(t.world.fingerprint() + "\n" + t.agent->key()).second) t.check_runnable();
    }
}

std::string TrialConfig::world_label() const { return world.is_none() && returns ? returns->label() : world.label(); }

std::string TrialConfig::condition_label() const {
    return condition.empty() ? world_label() + "_" + model.name : condition;
}

std::string TrialConfig::name() const { return condition_label() + "_seed" + std::to_string(seed); }

std::string TrialConfig::walk_key() const {
    // What older trials lack (returns, weights) is added only when present: their text is unchanged.
    return "world: " + world.fingerprint() + "\nprotocol:\n" + params::yaml_lines(Protocol::table(), protocol, "  ") +
           agent->key() + (returns ? returns->key() : "") + "seed: " + std::to_string(seed) + "\n";
}

std::string TrialConfig::canonical() const {
    // The analysis keys, with `extent` before decoding_templates as trial files have always had it.
    std::string lines = params::yaml_lines(analysis::AnalysisParams::table(), analysis, "  ");
    std::string extent = arena_extent ? "arena" : "data";
    if (!arena_extent && analysis.extent)  // fixed bounds (rare): named in full, so they change the fingerprint
        extent = params::to_text(std::vector<double>{analysis.extent->xmin, analysis.extent->xmax,
                                                     analysis.extent->ymin, analysis.extent->ymax});
    lines.insert(lines.find("  decoding_templates:"), "  extent: " + extent + "\n");
    return walk_key() + config::model_to_yaml(model) + (weights ? weights->key() : "") + "analysis:\n" + lines +
           (navigation ? navigation->canonical() : "");
}

analysis::AnalysisParams TrialConfig::analysis_params(const WorldDescription& w) const {
    analysis::AnalysisParams params = analysis;
    if (agent->dims() == 3 && w.flight) {  // voxels over the flight volume (docs/flying.md#analysis)
        const auto box = w.flight->bounds();
        params.volume =
            analysis::Box3{box.min().x(), box.max().x(), box.min().y(), box.max().y(), box.min().z(), box.max().z()};
    }
    if (arena_extent && !w.walkable.points.empty()) {
        const auto box = w.walkable.bounds();
        params.extent = analysis::Extent{box.min().x(), box.max().x(), box.min().y(), box.max().y()};
    }
    return params;
}

bool TrialConfig::place_cells_untrained() const {
    return !weights && protocol.kind == Protocol::Kind::explore_then_sample && !(protocol.explore_hours > 0);
}

std::string TrialConfig::place_weights() const {
    if (protocol.kind == Protocol::Kind::online || protocol.explore_hours > 0) return "learned";
    return weights ? "trained" : "untrained";
}

std::string TrialConfig::fingerprint() const {
    std::ostringstream os;
    os << std::hex << std::setw(16) << std::setfill('0') << text_hash(canonical());
    return os.str();
}

}  // namespace bvc3d

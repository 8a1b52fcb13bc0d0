#include "bvc3d/experiment/trial_config.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/random.hpp"

namespace bvc3d {

namespace {


std::uint64_t text_hash(const std::string& s) {
    std::uint64_t h = 0x6276633364ull;
    for (unsigned char c : s) h = hash_u64(h, c, 0x9e37);
    return h;
}

}  // namespace

WorldDescription WorldSpec::resolve() const { return config::resolve_world(source, tilt_deg, lean); }

std::string WorldSpec::label() const {
    if (source == "cross") {
        std::string l = "cross-" + format_number(tilt_deg.value_or(0.0));
        return lean == "+x+y" ? l : l + "_" + lean;
    }
    const auto presets = config::world_preset_names();
    if (std::find(presets.begin(), presets.end(), source) != presets.end()) return source;
    return std::filesystem::path(source).stem().string();
}

std::string WorldSpec::fingerprint() const {
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
    return fp;
}

void Protocol::validate() const {
    auto ok = [](double h) { return std::isfinite(h) && h >= 0; };
    if (!ok(explore_hours)) throw InputError("explore_hours must be a non-negative number of hours");
    if (!ok(sample_hours) || sample_hours <= 0) throw InputError("sample_hours must be a positive number of hours");
}

std::string protocol_name(Protocol::Kind k) { return k == Protocol::Kind::online ? "online" : "explore_then_sample"; }

Protocol::Kind parse_protocol(const std::string& name) {
    if (name == "explore_then_sample" || name == "paper") return Protocol::Kind::explore_then_sample;
    if (name == "online") return Protocol::Kind::online;
    throw InputError("protocol '" + name + "' is not one of explore_then_sample, online");
}

void TrialConfig::validate() const {
    model.validate();
    protocol.validate();
    robot.validate();
    analysis.validate();
    // Decoding compares two halves of the recorded samples: at least two model steps are needed.
    if (protocol.sample_hours * 3600.0 < 2.0 * robot.model_dt)
        throw InputError("sample_hours = " + format_number(protocol.sample_hours) + " h records fewer than 2 model steps (" +
                         format_number(robot.model_dt) + " s each)");
}

std::string TrialConfig::condition_label() const {
    return condition.empty() ? world.label() + "_" + model.name : condition;
}

std::string TrialConfig::name() const { return condition_label() + "_seed" + std::to_string(seed); }

std::string TrialConfig::walk_key() const {
    std::ostringstream os;
    os << "world: " << world.fingerprint() << "\nprotocol:\n  kind: " << protocol_name(protocol.kind)
       << "\n  explore_hours: " << format_number(protocol.explore_hours) << "\n  sample_hours: " << format_number(protocol.sample_hours)
       << "\n  record_bvc: " << (protocol.record_bvc ? "true" : "false") << "\nrobot:\n  radius: " << format_number(robot.radius)
       << "\n  height: " << format_number(robot.height) << "\n  speed: " << format_number(robot.speed) << "\n  turn_rate: " << format_number(robot.turn_rate)
       << "\n  model_dt: " << format_number(robot.model_dt) << "\n  n_walk: " << robot.n_walk << "\n  turn_sd: " << format_number(robot.turn_sd)
       << "\n  min_update_move: " << format_number(robot.min_update_move) << "\nseed: " << seed << "\n";
    return os.str();
}

std::string TrialConfig::canonical() const {
    std::ostringstream os;
    os << walk_key() << config::model_to_yaml(model) << "analysis:\n  gridsize: " << analysis.gridsize
       << "\n  quantile: " << format_number(analysis.quantile) << "\n  eps: " << format_number(analysis.dbscan.eps)
       << "\n  min_samples: " << analysis.dbscan.min_samples << "\n  d_th: " << format_number(analysis.d_th)
       << "\n  extent: " << (arena_extent ? "arena" : "data")
       << "\n  decoding_templates: " << analysis::decoding_templates_name(analysis.decoding_templates) << "\n";
    return os.str();
}

std::string TrialConfig::fingerprint() const {
    std::ostringstream os;
    os << std::hex << std::setw(16) << std::setfill('0') << text_hash(canonical());
    return os.str();
}

}  // namespace bvc3d

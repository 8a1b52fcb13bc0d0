#include "bvc3d/experiment/trial_config.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/random.hpp"

namespace bvc3d {

namespace {

std::string fmt(double x) {
    std::ostringstream os;
    os << std::setprecision(17) << x;
    return os.str();
}

std::uint64_t text_hash(const std::string& s) {
    std::uint64_t h = 0x6276633364ull;
    for (unsigned char c : s) h = hash_u64(h, c, 0x9e37);
    return h;
}

}  // namespace

WorldDescription WorldSpec::resolve() const { return config::resolve_world(source, tilt_deg, lean); }

std::string WorldSpec::label() const {
    if (source == "cross") {
        std::string l = "cross-" + fmt(tilt_deg.value_or(0.0));
        return lean == "+x+y" ? l : l + "_" + lean;
    }
    const auto presets = config::world_preset_names();
    if (std::find(presets.begin(), presets.end(), source) != presets.end()) return source;
    return std::filesystem::path(source).stem().string();
}

std::string WorldSpec::fingerprint() const {
    const auto presets = config::world_preset_names();
    if (std::find(presets.begin(), presets.end(), source) != presets.end())
        return "preset " + source + " tilt " + fmt(tilt_deg.value_or(0.0)) + " lean " + lean;
    std::ifstream in(source);
    std::stringstream text;
    text << in.rdbuf();
    return "file " + std::filesystem::path(source).filename().string() + " " + std::to_string(text_hash(text.str()));
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

std::string TrialConfig::condition_label() const {
    return condition.empty() ? world.label() + "_" + model.name : condition;
}

std::string TrialConfig::name() const { return condition_label() + "_seed" + std::to_string(seed); }

std::string TrialConfig::canonical() const {
    std::ostringstream os;
    os << "world: " << world.fingerprint() << "\n"
       << config::model_to_yaml(model) << "protocol:\n  kind: " << protocol_name(protocol.kind)
       << "\n  explore_hours: " << fmt(protocol.explore_hours) << "\n  sample_hours: " << fmt(protocol.sample_hours)
       << "\n  record_bvc: " << (protocol.record_bvc ? "true" : "false") << "\nrobot:\n  radius: " << fmt(robot.radius)
       << "\n  height: " << fmt(robot.height) << "\n  speed: " << fmt(robot.speed) << "\n  turn_rate: " << fmt(robot.turn_rate)
       << "\n  model_dt: " << fmt(robot.model_dt) << "\n  n_walk: " << robot.n_walk << "\n  turn_sd: " << fmt(robot.turn_sd)
       << "\n  min_update_move: " << fmt(robot.min_update_move) << "\nanalysis:\n  gridsize: " << analysis.gridsize
       << "\n  quantile: " << fmt(analysis.quantile) << "\n  eps: " << fmt(analysis.dbscan.eps)
       << "\n  min_samples: " << analysis.dbscan.min_samples << "\n  d_th: " << fmt(analysis.d_th)
       << "\n  extent: " << (arena_extent ? "arena" : "data") << "\nseed: " << seed << "\n";
    return os.str();
}

std::string TrialConfig::fingerprint() const {
    std::ostringstream os;
    os << std::hex << std::setw(16) << std::setfill('0') << text_hash(canonical());
    return os.str();
}

}  // namespace bvc3d

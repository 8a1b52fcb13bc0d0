#include "bvc3d/config/model_yaml.hpp"

#include <filesystem>
#include <sstream>

#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d::config {

namespace {

void read_bvc(const YamlView& v, BvcParams& b) {
    read_fields(v,
                {{"n_dir", &b.n_dir},
                 {"n_per_axis", &b.n_per_axis},
                 {"max_dist", &b.max_dist},
                 {"sigma_r", &b.sigma_r},
                 {"sigma_theta", &b.sigma_theta},
                 {"sigma_phi", &b.sigma_phi},
                 {"norm_constant", &b.norm_constant}},
                {"elevations", "elevations_deg", "normalization", "reading"});
    if (v.has("elevations") && v.has("elevations_deg")) v.fail("give 'elevations' (rad) or 'elevations_deg', not both");
    if (v.has("elevations")) {
        b.elevations = v["elevations"].is_sequence() ? v["elevations"].as_doubles() : std::vector<double>{};
        if (!v["elevations"].is_sequence() && !v["elevations"].node().IsNull())
            v["elevations"].fail("expected a list of elevations in radians (empty for the 2-D model)");
    }
    if (v.has("elevations_deg")) {
        b.elevations.clear();
        for (double d : v["elevations_deg"].as_doubles()) b.elevations.push_back(deg_to_rad(d));
    }
    for (double e : b.elevations)
        if (std::abs(e) > pi / 2) v.fail_key("elevations", "must lie within ±π/2 rad");
    if (b.n_dir < 1) v["n_dir"].fail("must be >= 1");
    if (b.n_per_axis < 1) v["n_per_axis"].fail("must be >= 1");
    require_positive(v, "max_dist", b.max_dist);
    require_positive(v, "sigma_r", b.sigma_r);
    require_positive(v, "sigma_theta", b.sigma_theta);
    require_positive(v, "sigma_phi", b.sigma_phi);
    require_positive(v, "norm_constant", b.norm_constant);
    try {
        if (v.has("normalization")) b.normalization = parse_bvc_normalization(v["normalization"].as_string());
    } catch (const InputError& e) {
        v["normalization"].fail(e.what());
    }
    try {
        if (v.has("reading")) b.reading = parse_bvc_reading(v["reading"].as_string());
    } catch (const InputError& e) {
        v["reading"].fail(e.what());
    }
    try {
        b.validate();
    } catch (const InputError& e) {
        v.fail(e.what());
    }
}

void read_place(const YamlView& v, PlaceParams& p) {
    read_fields(v, {{"n_place", &p.n_place},
                    {"p_connect", &p.p_connect},
                    {"dt_over_tau", &p.dt_over_tau},
                    {"gamma_pb", &p.gamma_pb},
                    {"gamma_pp", &p.gamma_pp},
                    {"gain", &p.gain},
                    {"eta", &p.eta},
                    {"alpha_pb", &p.alpha_pb}});
    if (p.n_place < 1) v["n_place"].fail("must be >= 1");
    require_range(v, "p_connect", p.p_connect, 0.0, 1.0);
    require_range(v, "dt_over_tau", p.dt_over_tau, 1e-12, 1.0);
    require_positive(v, "gain", p.gain);
    require_range(v, "eta", p.eta, 0.0, 1e6);
    require_positive(v, "alpha_pb", p.alpha_pb);
}


}  // namespace

ModelSpec model_from_yaml(const YamlView& v) {
    v.expect_map({"name", "base", "sensor", "bvc", "place"});
    ModelSpec m;
    if (v.has("base")) {
        try {
            m = model_preset(v["base"].as_string());
        } catch (const InputError& e) {
            v["base"].fail(e.what());
        }
    } else {
        m = model_preset("3d-0.2");
    }
    // Unnamed: a model file is named after the file; an inline model after its base, marked as
    // changed when it changes anything.
    const std::string base_name = m.name;
    const bool inline_model = !v.path().empty();
    const bool changed = v.has("sensor") || v.has("bvc") || v.has("place");
    m.name = v.get("name", inline_model ? base_name + (changed ? "-custom" : "")
                                        : std::filesystem::path(v.file()).stem().string());
    if (v.has("sensor")) {
        const YamlView s = v["sensor"];
        if (s.is_scalar()) {
            const std::string name = s.as_string();
            if (name == "horizontal") m.sensor = LidarSpec::horizontal();
            else if (name == "spherical") m.sensor = LidarSpec::spherical();
            else s.fail("expected horizontal, spherical, or a sensor mapping");
        } else {
            m.sensor = sensor_from_yaml(s);
        }
    }
    if (v.has("bvc")) read_bvc(v["bvc"], m.bvc);
    if (v.has("place")) read_place(v["place"], m.place);
    return m;
}

ModelSpec resolve_model(const std::string& name) {
    const auto presets = model_preset_names();
    if (std::find(presets.begin(), presets.end(), name) != presets.end()) return model_preset(name);
    std::error_code ec;
    if (!std::filesystem::exists(name, ec)) return model_preset(name);  // throws the "unknown model" error
    return model_from_yaml(YamlView::load_file(name));
}

std::string model_to_yaml(const ModelSpec& m) {
    std::ostringstream os;
    os << "name: " << m.name << "\n";
    os << "sensor:\n  name: " << m.sensor.name << "\n  elevations: [";
    for (std::size_t i = 0; i < m.sensor.elevations.size(); ++i) os << (i ? ", " : "") << format_number(m.sensor.elevations[i]);
    os << "]\n  azimuth_count: " << m.sensor.azimuth_count << "\n  azimuth_offset: " << format_number(m.sensor.azimuth_offset)
       << "\n  height: " << format_number(m.sensor.height) << "\n  max_range: " << format_number(m.sensor.max_range)
       << "\n  range_noise_sd: " << format_number(m.sensor.range_noise_sd) << "\n  dropout: " << format_number(m.sensor.dropout) << "\n";
    os << "bvc:\n  elevations: [";
    for (std::size_t i = 0; i < m.bvc.elevations.size(); ++i) os << (i ? ", " : "") << format_number(m.bvc.elevations[i]);
    os << "]\n  n_dir: " << m.bvc.n_dir << "\n  n_per_axis: " << m.bvc.n_per_axis << "\n  max_dist: " << format_number(m.bvc.max_dist)
       << "\n  sigma_r: " << format_number(m.bvc.sigma_r) << "\n  sigma_theta: " << format_number(m.bvc.sigma_theta)
       << "\n  sigma_phi: " << format_number(m.bvc.sigma_phi) << "\n  normalization: " << to_string(m.bvc.normalization)
       << "\n  norm_constant: " << format_number(m.bvc.norm_constant) << "\n  reading: " << to_string(m.bvc.reading) << "\n";
    const auto& p = m.place;
    os << "place:\n  n_place: " << p.n_place << "\n  p_connect: " << format_number(p.p_connect) << "\n  dt_over_tau: " << format_number(p.dt_over_tau)
       << "\n  gamma_pb: " << format_number(p.gamma_pb) << "\n  gamma_pp: " << format_number(p.gamma_pp) << "\n  gain: " << format_number(p.gain)
       << "\n  eta: " << format_number(p.eta) << "\n  alpha_pb: " << format_number(p.alpha_pb) << "\n";
    return os.str();
}

}  // namespace bvc3d::config

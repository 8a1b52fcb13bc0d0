#include "bvc3d/recorder/trial_file.hpp"

#include <sstream>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/recorder/hdf5_io.hpp"

namespace bvc3d {

namespace {

template <class T>
std::vector<T> column(const Eigen::Ref<const Eigen::VectorXd>& v) {
    return std::vector<T>(v.data(), v.data() + v.size());
}

void write_metrics(hid_t f, const analysis::TrialMetrics& m, const analysis::AnalysisParams& p) {
    const auto g = h5::create_group(f, "metrics");
    for (const auto& [name, value] : scalar_metrics(m)) h5::write_attr(g, name, value);
    // How they were computed, so that `bvc3d analyze` starts from the same parameters.
    h5::write_attr(g, "gridsize", static_cast<std::int64_t>(p.gridsize));
    h5::write_attr(g, "quantile", p.quantile);
    h5::write_attr(g, "eps", p.dbscan.eps);
    h5::write_attr(g, "min_samples", static_cast<std::int64_t>(p.dbscan.min_samples));
    h5::write_attr(g, "d_th", p.d_th);
    h5::write_attr(g, "decoding_templates", analysis::decoding_templates_name(p.decoding_templates));
    if (p.extent) h5::write(g, "extent", std::vector<double>{p.extent->xmin, p.extent->xmax, p.extent->ymin, p.extent->ymax}, {4}, false);
    const auto& bins = m.maps.bins;
    const std::size_t nb = static_cast<std::size_t>(bins.size()), nc = static_cast<std::size_t>(m.maps.map.cols());
    h5::write(g, "modality", std::vector<std::int64_t>(m.modality.begin(), m.modality.end()), {m.modality.size()});
    h5::write(g, "bin_centers", std::vector<double>(bins.centers.data(), bins.centers.data() + 2 * nb), {nb, 2});
    h5::write(g, "bin_counts", std::vector<std::int64_t>(bins.counts.begin(), bins.counts.end()), {nb});
    h5::write(g, "sai", column<double>(m.aliasing.sai), {nb});
    std::vector<float> maps(nb * nc);
    for (std::size_t i = 0; i < maps.size(); ++i) maps[i] = static_cast<float>(m.maps.map.data()[i]);
    h5::write(g, "rate_maps", maps, {nb, nc});
    h5::write(g, "peak_rate", m.cells.peak_rate, {nc});
    h5::write(g, "field_area", m.cells.field_area, {nc});
    h5::write(g, "spatial_info", m.cells.spatial_info, {nc});
}

}  // namespace

const std::vector<std::string>& scalar_metric_names() {
    static const std::vector<std::string> names{"frac_active", "mean_mi_active", "frac_multimodal",
                                                "msai",        "decode_median_m", "decode_mean_m",
                                                "n_bins",      "n_decoded",      "n_undecoded"};
    return names;
}

std::vector<std::pair<std::string, double>> scalar_metrics(const analysis::TrialMetrics& m) {
    const double values[] = {m.modality_summary.frac_active,
                             m.modality_summary.mean_mi_active,
                             m.modality_summary.frac_multimodal,
                             m.aliasing.msai,
                             m.decoding.median_m,
                             m.decoding.mean_m,
                             static_cast<double>(m.maps.bins.size()),
                             static_cast<double>(m.decoding.n_decoded),
                             static_cast<double>(m.decoding.n_undecoded)};
    std::vector<std::pair<std::string, double>> out;
    for (std::size_t i = 0; i < scalar_metric_names().size(); ++i) out.emplace_back(scalar_metric_names()[i], values[i]);
    return out;
}

void write_trial_file(const std::filesystem::path& path, const TrialConfig& config, const GroupResult& group,
                      std::size_t model_index, const analysis::TrialMetrics& metrics,
                      const analysis::AnalysisParams& params) {
    const ModelRecord& rec = group.models.at(model_index);
    const std::size_t n = group.t.size();
    AtomicFile out(path);
    {
        auto lock = h5::hdf5_lock();
        const auto f = h5::create_file(out.temp_path().string());
        h5::write_attr(f, "format", std::string("bvc3d-trial"));
        h5::write_attr(f, "format_version", static_cast<std::int64_t>(trial_file_format_version));
        h5::write_attr(f, "name", config.name());
        h5::write_attr(f, "condition", config.condition_label());
        std::string swept;
        for (const auto& [k, v] : config.swept) swept += k + "=" + v + "\n";
        h5::write_attr(f, "swept", swept);
        h5::write_attr(f, "world", config.world.label());
        h5::write_attr(f, "world_source", config.world.source);
        if (const auto tilt = config.world.resolve().tilt_deg) h5::write_attr(f, "tilt_deg", *tilt);
        h5::write_attr(f, "model", config.model.name);
        h5::write_attr(f, "sensor", config.model.sensor.name);
        h5::write_attr(f, "seed", static_cast<std::int64_t>(config.seed));
        h5::write_attr(f, "protocol", protocol_name(config.protocol.kind));
        h5::write_attr(f, "explore_hours", config.protocol.explore_hours);
        h5::write_attr(f, "sample_hours", config.protocol.sample_hours);
        h5::write_attr(f, "config", config.canonical());
        h5::write_attr(f, "fingerprint", config.fingerprint());

        const auto s = h5::create_group(f, "samples");
        h5::write(s, "t", group.t, {n});
        h5::write(s, "x", group.x, {n});
        h5::write(s, "y", group.y, {n});
        h5::write(s, "heading", group.heading, {n});
        h5::write(s, "rates", rec.rates, {n, static_cast<std::size_t>(rec.n_place)});
        if (!rec.bvc.empty()) h5::write(s, "bvc_rates", rec.bvc, {n, static_cast<std::size_t>(rec.n_bvc)});
        h5::write(f, "weights", rec.weights, {static_cast<std::size_t>(rec.n_place), static_cast<std::size_t>(rec.n_bvc)});

        const auto w = h5::create_group(f, "walk");
        h5::write_attr(w, "explore_steps", group.stats.explore_steps);
        h5::write_attr(w, "sample_steps", group.stats.sample_steps);
        h5::write_attr(w, "bumps", group.stats.bumps);
        h5::write_attr(w, "full_scan_fallbacks", group.stats.full_scan_fallbacks);
        h5::write_attr(w, "end_time", group.stats.end_time);
        write_metrics(f, metrics, params);
    }
    out.commit();
}

std::optional<std::string> trial_file_fingerprint(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;
    try {
        auto lock = h5::hdf5_lock();
        const auto f = h5::open_file(path.string());
        if (h5::read_attr_string(f, "format") != "bvc3d-trial") return std::nullopt;
        if (!h5::exists(f, "metrics")) return std::nullopt;
        return h5::read_attr_string(f, "fingerprint");
    } catch (const InputError&) {
        return std::nullopt;
    }
}

namespace {
h5::Handle open_trial(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw InputError("trial file '" + path.string() + "' does not exist");
    auto f = h5::open_file(path.string());
    std::string format;
    try {
        format = h5::read_attr_string(f, "format");
    } catch (const InputError&) {
    }
    if (format != "bvc3d-trial") throw InputError("'" + path.string() + "' is not a bvc3d trial file");
    return f;
}

TrialIdentity read_identity(hid_t f) {
    TrialIdentity id;
    id.name = h5::read_attr_string(f, "name");
    id.world = h5::read_attr_string(f, "world");
    id.model = h5::read_attr_string(f, "model");
    id.seed = static_cast<std::uint64_t>(h5::read_attr_int(f, "seed"));
    id.tilt_deg = h5::exists_attr(f, "tilt_deg") ? h5::read_attr_double(f, "tilt_deg") : NAN;
    // Files from before conditions were recorded: the paper's condition, model and world.
    id.condition = h5::exists_attr(f, "condition") ? h5::read_attr_string(f, "condition") : id.world + "_" + id.model;
    std::istringstream swept(h5::exists_attr(f, "swept") ? h5::read_attr_string(f, "swept") : std::string());
    for (std::string line; std::getline(swept, line);) {
        const auto eq = line.find('=');
        if (eq != std::string::npos) id.swept.emplace_back(line.substr(0, eq), line.substr(eq + 1));
    }
    return id;
}
}  // namespace

TrialFileData read_trial_samples(const std::filesystem::path& path) {
    auto lock = h5::hdf5_lock();
    const auto f = open_trial(path);
    TrialFileData d;
    static_cast<TrialIdentity&>(d) = read_identity(f);
    d.protocol = h5::read_attr_string(f, "protocol");
    d.config = h5::read_attr_string(f, "config");
    const auto g = h5::open_group(f, "metrics");
    if (h5::exists_attr(g, "gridsize")) {
        d.analysis.gridsize = static_cast<int>(h5::read_attr_int(g, "gridsize"));
        d.analysis.quantile = h5::read_attr_double(g, "quantile");
        d.analysis.dbscan.eps = h5::read_attr_double(g, "eps");
        d.analysis.dbscan.min_samples = static_cast<int>(h5::read_attr_int(g, "min_samples"));
        d.analysis.d_th = h5::read_attr_double(g, "d_th");
    }
    // Files from before the template choice was recorded decoded with raw means.
    d.analysis.decoding_templates =
        h5::exists_attr(g, "decoding_templates")
            ? analysis::parse_decoding_templates(h5::read_attr_string(g, "decoding_templates"))
            : (h5::exists_attr(g, "gridsize") ? analysis::DecodingTemplates::rate_maps : analysis::DecodingTemplates::means);
    if (h5::exists(g, "extent")) {
        const auto e = h5::read_doubles(g, "extent");
        if (e.size() == 4) d.analysis.extent = analysis::Extent{e[0], e[1], e[2], e[3]};
    }
    const auto s = h5::open_group(f, "samples");
    d.x = h5::read_doubles(s, "x");
    d.y = h5::read_doubles(s, "y");
    const auto dims = h5::dims(s, "rates");
    if (dims.size() != 2 || dims[0] != d.x.size()) throw InputError("'" + path.string() + "': samples/rates has the wrong shape");
    const auto flat = h5::read_floats(s, "rates");
    d.rates = Eigen::Map<const analysis::RowMatrixXf>(flat.data(), static_cast<Eigen::Index>(dims[0]),
                                                      static_cast<Eigen::Index>(dims[1]));
    return d;
}

TrialSummaryRow read_trial_summary(const std::filesystem::path& path) {
    auto lock = h5::hdf5_lock();
    const auto f = open_trial(path);
    TrialSummaryRow r;
    static_cast<TrialIdentity&>(r) = read_identity(f);
    const auto g = h5::open_group(f, "metrics");
    for (const auto& name : scalar_metric_names()) r.metrics.emplace_back(name, h5::read_attr_double(g, name));
    return r;
}

}  // namespace bvc3d

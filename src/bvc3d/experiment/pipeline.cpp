#include "bvc3d/experiment/pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "bvc3d/analysis/metrics.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/episodes.hpp"
#include "bvc3d/recorder/checkpoint_file.hpp"

namespace bvc3d {

namespace {

template <class T>
NamedArray array(const char* name, std::vector<std::size_t> shape, std::vector<T> data, bool compress = true) {
    return NamedArray{name, std::move(shape), std::move(data), compress};
}

}  // namespace

analysis::Points sample_positions(const GroupResult& r, int dims) {
    const auto n = static_cast<Eigen::Index>(r.x.size());
    analysis::Points p(n, dims);
    for (Eigen::Index i = 0; i < n; ++i) {
        p(i, 0) = r.x[static_cast<std::size_t>(i)];
        p(i, 1) = r.y[static_cast<std::size_t>(i)];
        if (dims == 3) p(i, 2) = r.z[static_cast<std::size_t>(i)];
    }
    return p;
}

AnalyzedTrial analyze(const TrialConfig& t, const WorldDescription& world, const GroupResult& r, std::size_t model) {
    AnalyzedTrial a;
    a.params = t.analysis_params(world);
    const auto& rec = r.models.at(model);
    const auto n = static_cast<Eigen::Index>(r.x.size());
    const analysis::Points positions = sample_positions(r, t.agent->dims());
    const Eigen::Map<const analysis::RowMatrixXf> rates(rec.rates.data(), n, rec.n_place);
    a.metrics = analysis::analyze_trial<float>(positions, rates, a.params);
    // Every other recorded population, the same way.
    for (const PopulationRecord& p : rec.populations) {
        if (!p.recorded || p.cells == 0) continue;
        const Eigen::Map<const analysis::RowMatrixXf> cells(p.rates.data(), n, static_cast<Eigen::Index>(p.cells));
        a.populations.emplace_back(
            p.name, AnalyzedPopulation{analysis::analyze_trial<float>(positions, cells, a.params), a.params});
    }
    // A multiscale model's scales fused (docs/model-reference.md#multiscale-models): its place cells and each recorded
    // further scale (ModelSpec::place_scales), side by side, each scale's rate vector scaled to unit length per sample.
    std::vector<std::pair<const float*, std::size_t>> scales{{rec.rates.data(), static_cast<std::size_t>(rec.n_place)}};
    for (const std::string& name : t.model.place_scales())
        for (const PopulationRecord& p : rec.populations)
            if (p.name == name && p.recorded && p.cells > 0) scales.emplace_back(p.rates.data(), p.cells);
    if (scales.size() > 1) {
        std::size_t total = 0;
        for (const auto& sc : scales) total += sc.second;
        std::vector<float> fused(static_cast<std::size_t>(n) * total);
        for (std::size_t i = 0; i < static_cast<std::size_t>(n); ++i) {
            float* out = fused.data() + i * total;
            for (const auto& [scale_rates, cells] : scales) {
                const float* row = scale_rates + i * cells;
                double norm = 0;
                for (std::size_t j = 0; j < cells; ++j) norm += static_cast<double>(row[j]) * row[j];
                const double scale = norm > 0 ? 1.0 / std::sqrt(norm) : 0.0;
                for (std::size_t j = 0; j < cells; ++j) out[j] = static_cast<float>(row[j] * scale);
                out += cells;
            }
        }
        const Eigen::Map<const analysis::RowMatrixXf> cells(fused.data(), n, static_cast<Eigen::Index>(total));
        a.populations.emplace_back(
            fused_population, AnalyzedPopulation{analysis::analyze_trial<float>(positions, cells, a.params), a.params});
    }
    return a;
}

namespace {

// The group's world, or none for a trial without one (a replay).
std::optional<World> group_world(const std::vector<TrialConfig>& trials) {
    if (trials.front().world.is_none()) return std::nullopt;
    return World(trials.front().world.resolve());
}

// The episodes of each navigation trial of the group after its learning run (experiment/episodes.hpp): each trial's
// populations' states taken from the group's (its nodes: "bvc", "place", then its ModelSpec::populations, model after
// model), its NavigationRecord and the reward cells' weights after replay into its record.
void run_navigation(const World& world, const std::vector<TrialConfig>& trials, GroupResult& result,
                    const RunControl& control) {
    std::size_t first = 0;
    for (std::size_t k = 0; k < trials.size(); ++k) {
        const std::size_t nodes = 2 + trials[k].model.populations.size();
        const std::size_t from = first;
        first += nodes;
        if (!trials[k].navigation) continue;
        std::vector<std::vector<StateArray>> learned(std::make_move_iterator(result.states.begin() + from),
                                                     std::make_move_iterator(result.states.begin() + from + nodes));
        EpisodeOutcome done = run_episodes(world, trials[k], std::move(learned), EpisodeControl{control.stop, {}});
        NavigationRecord& rec = done.record;
        for (const auto& [name, value] : result.stats.agent_report) {
            if (name == "learn_s") rec.learn_s = value;
            if (name == "coverage") rec.coverage = value;
            if (name == "visits") rec.visits.push_back(static_cast<int>(value));
        }
        ModelRecord& model = result.models[k];
        model.navigation = {std::move(rec)};
        // What the trial keeps of its populations, as the episodes leave them (the reward cells' replayed weights).
        for (std::size_t j = 0; j < model.populations.size(); ++j)
            for (StateArray& kept : model.populations[j].kept)
                for (StateArray& now : done.states[2 + j])
                    if (now.name == kept.name) kept = std::move(now);
    }
    result.states.clear();
}

}  // namespace

GroupOutcome run_and_analyze(const std::vector<TrialConfig>& trials, const RunControl& control) {
    if (trials.empty()) throw InputError("a trial group needs at least one trial");
    const std::optional<World> world = group_world(trials);
    return run_and_analyze(world ? &*world : nullptr, trials, control);
}

GroupOutcome run_and_analyze(const World* world, const std::vector<TrialConfig>& trials, const RunControl& control) {
    if (trials.empty()) throw InputError("a trial group needs at least one trial");
    const WorldDescription none;
    GroupOutcome out;
    const bool navigating = std::any_of(trials.begin(), trials.end(), [](const auto& t) { return bool(t.navigation); });
    RunControl run = control;
    run.keep_states = run.keep_states || navigating;
    run.checkpoint_at_end = run.checkpoint_at_end || navigating;
    out.result = run_trial_group(world, trials, run);
    if (navigating) run_navigation(*world, trials, out.result, control);
    for (std::size_t k = 0; k < trials.size(); ++k) {
        if (!trials[k].protocol.records()) {  // nothing recorded to analyse (navigation's learning)
            out.trials.emplace_back();
            continue;
        }
        out.trials.push_back(analyze(trials[k], world ? world->description() : none, out.result, k));
        for (const auto& w : out.trials.back().metrics.warnings) {
            const std::string message = trials[k].name() + ": " + w;
            if (control.warn) control.warn(message);
            else std::fprintf(stderr, "bvc3d: warning: %s\n", message.c_str());
        }
    }
    return out;
}

GroupOutcome run_analyze_write(const std::vector<TrialConfig>& trials, const std::vector<std::filesystem::path>& paths,
                               const RunControl& control) {
    if (paths.size() != trials.size()) throw std::logic_error("one path per trial");
    GroupOutcome out = run_and_analyze(trials, control);
    const WorldDescription world = trials.front().world.is_none() ? WorldDescription{} : trials.front().world.resolve();
    for (std::size_t k = 0; k < trials.size(); ++k) {
        std::vector<std::pair<std::string, MetricsRecord>> populations;
        for (const auto& [name, p] : out.trials[k].populations)
            populations.emplace_back(name, metrics_record(p.metrics, p.params));
        write_trial_file(paths[k], trial_identity(trials[k], world), out.result, k,
                         trials[k].protocol.records() ? metrics_record(out.trials[k].metrics, out.trials[k].params,
                                                                       !trials[k].place_cells_untrained())
                                                      : MetricsRecord{},
                         populations);
    }
    if (!control.checkpoint.empty()) remove_checkpoint(control.checkpoint);
    return out;
}

TrialIdentity trial_identity(const TrialConfig& t, const WorldDescription& world) {
    TrialIdentity id;
    id.name = t.name();
    id.condition = t.condition_label();
    id.swept = t.swept;
    id.world = t.world_label();
    id.world_source = t.world.source;
    if (t.returns) id.data_source = t.returns->attributes();
    id.tilt_deg = world.tilt_deg.value_or(NAN);
    id.model = t.model.name;
    id.model_config = config::model_to_yaml(t.model);
    id.place_weights = t.place_weights();
    if (t.weights) id.place_weights_source = t.weights->source;
    id.sensor = t.returns ? t.returns->sensor_label() : t.model.sensor.name;
    id.seed = t.seed;
    id.protocol = protocol_name(t.protocol.kind);
    id.explore_hours = t.protocol.explore_hours;
    id.sample_hours = t.protocol.sample_hours;
    id.config = t.canonical();
    id.fingerprint = t.fingerprint();
    id.dims = t.agent->dims();
    return id;
}

MetricsRecord metrics_record(const analysis::TrialMetrics& m, const analysis::AnalysisParams& p, bool scalars) {
    MetricsRecord r;
    if (scalars) r.scalars = analysis::scalar_metrics(m);
    // How they were computed, so that `bvc3d analyze` starts from the same parameters (keys quiet at
    // their defaults only when set, as in canonical text: files read back without them get the default).
    static const analysis::AnalysisParams defaults;
    for (const auto& f : analysis::AnalysisParams::table().fields())
        if (!f.quiet_default || f.get(p) != f.get(defaults)) r.parameters.emplace_back(f.key, f.get(p));
    if (p.extent)
        r.arrays.push_back(array(
            "extent", {4}, std::vector<double>{p.extent->xmin, p.extent->xmax, p.extent->ymin, p.extent->ymax}, false));
    if (m.dims == 3 && p.volume) {
        const auto& v = *p.volume;
        r.arrays.push_back(
            array("volume", {6}, std::vector<double>{v.xmin, v.xmax, v.ymin, v.ymax, v.zmin, v.zmax}, false));
    }
    const auto& bins = m.maps.bins;
    const std::size_t nb = static_cast<std::size_t>(bins.size()), nc = static_cast<std::size_t>(m.maps.map.cols());
    const std::size_t dims = static_cast<std::size_t>(bins.centers.cols());
    r.arrays.push_back(
        array("modality", {m.modality.size()}, std::vector<std::int64_t>(m.modality.begin(), m.modality.end())));
    r.arrays.push_back(
        array("bin_centers", {nb, dims}, std::vector<double>(bins.centers.data(), bins.centers.data() + nb * dims)));
    r.arrays.push_back(array("bin_counts", {nb}, std::vector<std::int64_t>(bins.counts.begin(), bins.counts.end())));
    r.arrays.push_back(array("sai", {nb}, std::vector<double>(m.aliasing.sai.data(), m.aliasing.sai.data() + nb)));
    std::vector<float> maps(nb * nc);
    for (std::size_t i = 0; i < maps.size(); ++i) maps[i] = static_cast<float>(m.maps.map.data()[i]);
    r.arrays.push_back(array("rate_maps", {nb, nc}, std::move(maps)));
    r.arrays.push_back(array("peak_rate", {nc}, m.cells.peak_rate));
    r.arrays.push_back(array("field_area", {nc}, m.cells.field_area));
    r.arrays.push_back(array("spatial_info", {nc}, m.cells.spatial_info));
    if (m.dims == 3) r.arrays.push_back(array("isotropy", {nc}, m.isotropy));
    return r;
}

analysis::AnalysisParams stored_analysis_params(const TrialFileData& file, const std::filesystem::path& path) {
    analysis::AnalysisParams p = analysis::AnalysisParams::defaults(file.dims);
    const auto& table = analysis::AnalysisParams::table();
    const auto where = [&](const std::string& name) {
        return "trial file '" + path.string() + "': attribute '/metrics/" + name + "'";
    };
    bool any = false;
    for (const auto& [name, value] : file.metric_attributes) {
        const auto* f = table.find(name);
        if (!f) continue;
        params::Value v = value;
        const bool number = f->kind == params::Kind::real || f->kind == params::Kind::integer;
        if (f->kind == params::Kind::integer && std::holds_alternative<double>(v)) {
            const double d = std::get<double>(v);
            if (!(std::abs(d) < 1e15) || d != std::floor(d)) throw InputError(where(name) + " must be a whole number");
            v = static_cast<long long>(d);
        }
        if (f->kind == params::Kind::real && std::holds_alternative<long long>(v))
            v = static_cast<double>(std::get<long long>(v));
        const bool right_type = number ? (std::holds_alternative<double>(v) || std::holds_alternative<long long>(v))
                                       : std::holds_alternative<std::string>(v);
        if (!right_type) throw InputError(where(name) + " has the wrong type");
        try {
            table.set(p, *f, v);
            any = true;
        } catch (const params::ParamError& e) {
            throw InputError(where(name) + ": " + e.reason());
        } catch (const std::bad_variant_access&) {
            throw InputError(where(name) + " has the wrong type");
        }
    }
    // Files from before the template choice was recorded decoded with raw means.
    const bool has_templates = std::any_of(file.metric_attributes.begin(), file.metric_attributes.end(),
                                           [](const auto& a) { return a.first == "decoding_templates"; });
    if (!has_templates && !any) p.decoding_templates = analysis::DecodingTemplates::means;
    if (file.extent && file.extent->size() == 4)
        p.extent = analysis::Extent{(*file.extent)[0], (*file.extent)[1], (*file.extent)[2], (*file.extent)[3]};
    if (file.volume && file.volume->size() == 6) {
        const auto& v = *file.volume;
        p.volume = analysis::Box3{v[0], v[1], v[2], v[3], v[4], v[5]};
    }
    return p;
}

analysis::Extent arena_extent(const TrialFileData& file, const std::filesystem::path& path) {
    WorldSpec spec;
    spec.source = file.world_source.empty() ? std::string("cross") : file.world_source;
    if (spec.source == "cross" && std::isfinite(file.tilt_deg)) spec.tilt_deg = file.tilt_deg;
    WorldDescription world;
    try {
        world = spec.resolve();
    } catch (const InputError& e) {
        throw InputError("--extent arena: the world of trial file '" + path.string() + "' ('" + spec.source +
                         "') cannot be loaded again (" + e.what() + "); give the bounds as XMIN,XMAX,YMIN,YMAX");
    }
    const auto box = world.walkable.bounds();
    return analysis::Extent{box.min().x(), box.max().x(), box.min().y(), box.max().y()};
}

bool trial_file_complete(const std::filesystem::path& path, const TrialConfig& t) {
    const auto stamp = read_trial_stamp(path);
    if (!stamp || stamp->fingerprint != t.fingerprint()) return false;
    if (!t.protocol.records()) return !t.navigation || stamp->navigation;  // nothing recorded to analyse
    if (t.place_cells_untrained()) return true;                            // no metrics written
    for (const auto& name : analysis::metric_names(t.agent->dims()))
        if (std::find(stamp->metric_attributes.begin(), stamp->metric_attributes.end(), name) ==
            stamp->metric_attributes.end())
            return false;
    return true;
}

}  // namespace bvc3d

#include "bvc3d/experiment/trial_runner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <span>

#include "bvc3d/bvc/boundary_vector_layer.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/place/place_cell_network.hpp"
#include "bvc3d/recorder/checkpoint_file.hpp"

namespace bvc3d {

namespace {

// A return source shared by the group's models, and the rows of its beam table at least one needs.
struct SourceUse {
    std::shared_ptr<ReturnSource> source;
    std::vector<char> rows;
    Scan scan, full;
    bool full_read = false;
};

void check_group(const std::vector<TrialConfig>& trials) {
    if (trials.empty()) throw InputError("a trial group needs at least one trial");
    const TrialConfig& a = trials.front();
    for (const auto& b : trials) {
        b.validate();
        if (b.walk_key() != a.walk_key())
            throw InputError("trials in one group must share world, seed, protocol, agent and returns");
    }
}

// The group's running state: everything a checkpoint saves.
struct GroupRun {
    const std::vector<TrialConfig>& trials;
    const World* world;  // null: a trial without one
    std::unique_ptr<Agent> agent;
    std::vector<SourceUse> sources;
    std::vector<int> source_of;  // per model
    std::vector<BoundaryVectorLayer> layers;
    std::vector<BoundaryVectorLayer::ScanPlan> plans;  // per model; empty rows without a beam table
    // Models whose BVC layers differ only in their elevations (on one source) read their sums from
    // one layer that sums the union of their elevations once a step: shared[u], per model shared_of
    // (-1: sums its own). Each model keeps its own truncation bound: the same bits either way.
    struct SharedSums {
        int source;
        std::vector<std::size_t> models;
        std::unique_ptr<BoundaryVectorLayer> layer;
        BoundaryVectorLayer::ScanPlan plan;
    };
    std::vector<SharedSums> shared;
    std::vector<int> shared_of;
    std::vector<PlaceCellNetwork> nets;
    std::vector<std::vector<double>> bvc_rates;
    // Place-cell steps wait here until `block` of them are due; then each model takes them in one
    // PlaceCellNetwork::step_block, which reads its weights once for every 8 steps (a thread stepping
    // four models read 4 × 960 KB of weights per walk step otherwise, more than an L2 holds). A step's
    // BVC rates do not depend on the place cells, so only the timing changes, not a bit of the results.
    static constexpr std::size_t block = 16;
    std::vector<char> due_learn, due_record;
    std::vector<std::vector<double>> due_rates;  // per model: due_learn.size() × n_bvc
    GroupResult result;
    std::int64_t step_index = 0;
    std::size_t ckpt_segments = 0, ckpt_saved = 0;  // samples already in checkpoint segments

    GroupRun(const World* w, const std::vector<TrialConfig>& t, const SourceFactory& factory);
    int use_source(const ModelSpec& model, const SourceFactory& factory);
    void share_sums();
    void reserve_samples();
    bool model_rates(std::size_t i, const Pose& pose);
    void step(const ModelStep& s, bool learn, bool record);
    void run_place_cells();  // every due place-cell step, model by model
    GroupCheckpoint checkpoint(const std::string& fingerprint) const;
    void restore(const GroupCheckpoint& c);
};

GroupRun::GroupRun(const World* w, const std::vector<TrialConfig>& t, const SourceFactory& factory)
    : trials(t), world(w), agent(t.front().agent->make(w, t.front().seed)) {
    for (const auto& c : trials) {
        layers.emplace_back(c.model.bvc);
        nets.emplace_back(c.model.bvc.n_cells(), c.model.place, c.seed);
        if (c.weights) nets.back().set_weights(c.weights->values);
        bvc_rates.emplace_back(layers.back().n_cells());
        const int si = use_source(c.model, factory);
        source_of.push_back(si);
        const LidarSpec* table = sources[si].source->beam_table();
        plans.push_back(table ? layers.back().plan(*table) : BoundaryVectorLayer::ScanPlan{});
        for (std::size_t r = 0; r < plans.back().rows.size(); ++r) sources[si].rows[r] |= plans.back().rows[r];
        ModelRecord rec;
        rec.n_place = c.model.place.n_place;
        rec.n_bvc = c.model.bvc.n_cells();
        result.models.push_back(std::move(rec));
    }
    share_sums();
    due_rates.resize(nets.size());
    for (std::size_t i = 0; i < nets.size(); ++i) due_rates[i].reserve(block * bvc_rates[i].size());
    // Room for the samples a full recording phase can hold, so growing buffers never double past
    // it: with many models on one agent that matters.
    reserve_samples();
}

int GroupRun::use_source(const ModelSpec& model, const SourceFactory& factory) {
    std::shared_ptr<ReturnSource> made = factory ? factory(model, world) : nullptr;
    for (std::size_t i = 0; i < sources.size(); ++i) {
        const LidarSpec* table = sources[i].source->beam_table();
        if (made ? sources[i].source == made : table && table->same_beams(model.sensor)) return static_cast<int>(i);
    }
    if (!made) {
        if (!world)
            throw InputError("model '" + model.name +
                             "' has no source of returns: without a world its sensor cannot be cast");
        // Sensor noise: the trial's own stream, the same draws for every sensor of the group (common
        // random numbers: conditions that differ in their noise level see the same underlying draws).
        const std::uint64_t noise_seed =
            hash_u64(trials.front().seed, static_cast<std::uint64_t>(Stream::sensor_noise), 0);
        made = std::make_shared<RayCastSource>(*world, model.sensor, noise_seed);
    }
    const LidarSpec* table = made->beam_table();
    sources.push_back(SourceUse{made, std::vector<char>(table ? table->elevations.size() : 0, 0), {}, {}, false});
    return static_cast<int>(sources.size() - 1);
}

void GroupRun::share_sums() {
    for (std::size_t i = 0; i < layers.size(); ++i) {
        if (!sources[source_of[i]].source->beam_table()) continue;
        auto same = std::find_if(shared.begin(), shared.end(), [&](const SharedSums& g) {
            return g.source == source_of[i] && layers[i].can_share_sums(layers[g.models.front()].params());
        });
        if (same == shared.end()) same = shared.insert(shared.end(), SharedSums{source_of[i], {}, nullptr, {}});
        same->models.push_back(i);
    }
    for (SharedSums& g : shared) {
        BvcParams all = layers[g.models.front()].params();
        for (std::size_t i : g.models)
            for (double psi : layers[i].params().elevations)
                if (std::find(all.elevations.begin(), all.elevations.end(), psi) == all.elevations.end())
                    all.elevations.push_back(psi);
        // Alone, or too many layers to sum at once: each sums its own.
        if (g.models.size() < 2 ||
            static_cast<double>(all.elevations.size()) * all.n_dir * all.n_per_axis > BvcParams::max_cells)
            continue;
        g.layer = std::make_unique<BoundaryVectorLayer>(all);
        g.plan = g.layer->plan(*sources[g.source].source->beam_table());
    }
    std::erase_if(shared, [](const SharedSums& g) { return !g.layer; });
    shared_of.assign(layers.size(), -1);
    for (std::size_t u = 0; u < shared.size(); ++u)
        for (std::size_t i : shared[u].models) shared_of[i] = static_cast<int>(u);
}

void GroupRun::reserve_samples() {
    const auto& first = trials.front();
    const auto expected =
        static_cast<std::size_t>(first.protocol.sample_hours * 3600.0 * first.agent->steps_per_second()) + 64;
    for (auto* v : {&result.t, &result.x, &result.y, &result.z, &result.heading}) v->reserve(expected);
    for (auto& rec : result.models) {
        rec.rates.reserve(expected * rec.n_place);
        if (first.protocol.record_bvc) rec.bvc.reserve(expected * rec.n_bvc);
    }
}

// Model i's BVC rates from its source's returns of this step. A scan cast with a plan's rows whose
// pruning bound fails (almost nothing in view) is read again in full and summed exactly.
bool GroupRun::model_rates(std::size_t i, const Pose& pose) {
    SourceUse& u = sources[source_of[i]];
    if (u.source->beam_table() && pose.level() &&
        (shared_of[i] < 0 ? layers[i].rates_pruned(u.scan, plans[i], bvc_rates[i])
                          : layers[i].rates_pruned_shared(u.scan, plans[i], *shared[shared_of[i]].layer, bvc_rates[i])))
        return true;
    if (!u.source->beam_table() || !pose.level()) {
        layers[i].rates(u.scan, bvc_rates[i]);  // every return was read
        return true;
    }
    if (!u.full_read) u.source->returns(static_cast<std::uint64_t>(step_index), pose, {}, u.full);
    u.full_read = true;
    layers[i].rates(u.full, bvc_rates[i]);
    return false;
}

void GroupRun::step(const ModelStep& s, bool learn, bool record) {
    static const std::vector<char> all_rows;
    for (auto& u : sources) {
        u.source->returns(static_cast<std::uint64_t>(step_index), s.pose, s.pose.level() ? u.rows : all_rows, u.scan);
        u.full_read = false;
    }
    if (s.pose.level())
        for (const auto& g : shared) g.layer->sum_pruned(sources[g.source].scan, g.plan);
    for (std::size_t i = 0; i < layers.size(); ++i) {
        if (!model_rates(i, s.pose)) ++result.stats.full_scan_fallbacks;
        due_rates[i].insert(due_rates[i].end(), bvc_rates[i].begin(), bvc_rates[i].end());
        if (record && trials.front().protocol.record_bvc)
            for (double b : bvc_rates[i]) result.models[i].bvc.push_back(static_cast<float>(b));
    }
    due_learn.push_back(learn);
    due_record.push_back(record);
    if (due_learn.size() >= block) run_place_cells();
    if (record) {
        const Pose& logged = s.logged();  // the scan's pose unless the agent logs with a lag
        result.t.push_back(s.t);
        result.x.push_back(logged.x);
        result.y.push_back(logged.y);
        result.z.push_back(logged.z);
        result.heading.push_back(logged.heading);
    }
    ++step_index;
    result.stats.bumps += s.bumped;
    (record ? result.stats.sample_steps : result.stats.explore_steps) += 1;
}

void GroupRun::run_place_cells() {
    for (std::size_t i = 0; i < nets.size(); ++i) {
        const auto v = nets[i].step_block(due_rates[i], due_learn);
        auto& rec = result.models[i];
        const std::size_t n = static_cast<std::size_t>(nets[i].n_place());
        for (std::size_t k = 0; k < due_record.size(); ++k)
            if (due_record[k]) rec.rates.insert(rec.rates.end(), v.begin() + k * n, v.begin() + (k + 1) * n);
        due_rates[i].clear();
    }
    due_learn.clear();
    due_record.clear();
}

GroupCheckpoint GroupRun::checkpoint(const std::string& fingerprint) const {
    // The state, and only the samples recorded since the last checkpoint.
    GroupCheckpoint c;
    c.fingerprint = fingerprint;
    c.agent_state = agent->save_state();
    c.step_index = step_index;
    c.segments = ckpt_segments;
    c.saved = ckpt_saved;
    c.partial.stats = result.stats;
    const auto from = static_cast<std::ptrdiff_t>(ckpt_saved);
    for (auto [to, all] :
         {std::pair{&c.partial.t, &result.t}, std::pair{&c.partial.x, &result.x}, std::pair{&c.partial.y, &result.y},
          std::pair{&c.partial.z, &result.z}, std::pair{&c.partial.heading, &result.heading}})
        to->assign(all->begin() + from, all->end());
    for (std::size_t i = 0; i < nets.size(); ++i) {
        const auto& rec = result.models[i];
        ModelRecord m;
        m.n_place = rec.n_place;
        m.n_bvc = rec.n_bvc;
        m.rates.assign(rec.rates.begin() + from * rec.n_place, rec.rates.end());
        if (!rec.bvc.empty()) m.bvc.assign(rec.bvc.begin() + from * rec.n_bvc, rec.bvc.end());
        m.weights = nets[i].weights();
        c.partial.models.push_back(std::move(m));
        c.membrane.emplace_back(nets[i].membrane().begin(), nets[i].membrane().end());
        c.place_rates.emplace_back(nets[i].rates().begin(), nets[i].rates().end());
    }
    return c;
}

void GroupRun::restore(const GroupCheckpoint& c) {
    // Everything is checked before anything changes: a checkpoint that does not fit leaves the run
    // as it was, to start from the beginning.
    const auto mismatch = [] { throw InputError("its arrays do not match the group's models"); };
    if (c.partial.models.size() != nets.size() || c.membrane.size() != nets.size() ||
        c.place_rates.size() != nets.size())
        mismatch();
    for (std::size_t i = 0; i < nets.size(); ++i) {
        const auto& m = c.partial.models[i];
        if (m.n_place != result.models[i].n_place || m.n_bvc != result.models[i].n_bvc ||
            m.weights.size() != static_cast<std::size_t>(m.n_place) * static_cast<std::size_t>(m.n_bvc) ||
            c.membrane[i].size() != static_cast<std::size_t>(m.n_place) ||
            c.place_rates[i].size() != static_cast<std::size_t>(m.n_place))
            mismatch();
        for (float w : m.weights)
            if (!std::isfinite(w)) throw InputError("its weights are not finite");
    }
    agent->restore_state(c.agent_state);
    step_index = c.step_index;
    ckpt_segments = c.segments;
    ckpt_saved = c.saved;
    result = c.partial;
    reserve_samples();
    for (std::size_t i = 0; i < nets.size(); ++i) {
        nets[i].set_weights(result.models[i].weights);
        nets[i].set_state(c.membrane[i], c.place_rates[i]);
        result.models[i].weights.clear();
    }
}

}  // namespace

std::string group_fingerprint(const std::vector<TrialConfig>& trials) {
    std::string s;
    for (const auto& t : trials) s += t.fingerprint() + ";";
    return s;
}

GroupResult run_trial_group(const std::vector<TrialConfig>& trials, const RunControl& control) {
    check_group(trials);
    if (trials.front().world.is_none()) return run_trial_group(nullptr, trials, control);
    const World world(trials.front().world.resolve());
    return run_trial_group(&world, trials, control);
}

GroupResult run_trial_group(const World* world, const std::vector<TrialConfig>& trials, const RunControl& control,
                            const SourceFactory& sources) {
    check_group(trials);
    const auto& returns = trials.front().returns;
    GroupRun run(world, trials, sources || !returns ? sources : returns->factory(trials.front().seed));
    const std::string fingerprint = group_fingerprint(trials);
    if (!control.checkpoint.empty()) {
        const auto warn = [&](const std::string& message) {
            if (control.warn) control.warn(message);
            else std::fprintf(stderr, "bvc3d: warning: %s\n", message.c_str());
        };
        const auto saved = read_checkpoint(control.checkpoint);
        if (!saved.problem.empty()) {
            warn(saved.problem + "; the trial starts again from the beginning");
        } else if (saved.checkpoint && saved.checkpoint->fingerprint != fingerprint) {
            warn("checkpoint '" + control.checkpoint.string() +
                 "' belongs to another configuration; the trial starts from the beginning");
        } else if (saved.checkpoint) {
            try {
                run.restore(*saved.checkpoint);
            } catch (const InputError& e) {
                warn("checkpoint '" + control.checkpoint.string() + "' does not fit this trial (" + e.what() +
                     "); the trial starts again from the beginning");
            }
        }
    }
    const Protocol& p = trials.front().protocol;
    const bool online = p.kind == Protocol::Kind::online;
    const double t_explore = online ? 0.0 : p.explore_hours * 3600.0;
    const double t_end = t_explore + p.sample_hours * 3600.0;
    const double ckpt_every = control.checkpoint_minutes * 60.0;
    double next_ckpt = ckpt_every > 0 ? (std::floor(run.agent->time() / ckpt_every) + 1) * ckpt_every : INFINITY;

    for (std::int64_t n = 0;; ++n) {
        const bool sampling = run.agent->time() >= t_explore;
        const auto s = run.agent->next(sampling ? t_end : t_explore);
        if (!s) {
            if (sampling) break;
            if (run.agent->finished())
                throw InputError(
                    "the agent's path ends after " + format_number(run.agent->time() / 3600) +
                    " h, before the recorded phase begins (explore_hours = " + format_number(p.explore_hours) + ")");
            continue;  // exploration is over: go on sampling from here
        }
        run.step(*s, !sampling || online, sampling);
        if (control.progress && n % std::max<std::int64_t>(1, control.progress_every) == 0)
            control.progress(run.agent->time(), run.step_index);
        const bool stop = control.stop && n % 64 == 0 && control.stop->load();
        if (!control.checkpoint.empty() && (stop || run.agent->time() >= next_ckpt)) {
            run.run_place_cells();
            GroupCheckpoint c = run.checkpoint(fingerprint);
            write_checkpoint(control.checkpoint, c);
            run.ckpt_segments = c.segments;
            run.ckpt_saved = c.saved;
            while (next_ckpt <= run.agent->time()) next_ckpt += ckpt_every;
        }
        if (stop) throw Interrupted();
    }
    run.run_place_cells();
    if (control.progress) control.progress(run.agent->time(), run.step_index);
    for (std::size_t i = 0; i < run.nets.size(); ++i) run.result.models[i].weights = run.nets[i].weights();
    run.result.stats.end_time = run.agent->time();
    return std::move(run.result);
}

}  // namespace bvc3d

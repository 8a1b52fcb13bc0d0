#include "bvc3d/experiment/trial_runner.hpp"

#include <filesystem>
#include <sstream>

#include "bvc3d/core/error.hpp"
#include "bvc3d/recorder/checkpoint_file.hpp"

namespace bvc3d {

namespace {

// A sensor shared by the group's models, and the rows at least one of them needs.
struct SensorUse {
    LidarSpec spec;
    Lidar lidar;
    std::vector<char> rows;
    Scan scan, full;
    bool full_cast = false;
};

void check_group(const std::vector<TrialConfig>& trials) {
    if (trials.empty()) throw InputError("a trial group needs at least one trial");
    const TrialConfig& a = trials.front();
    for (const auto& b : trials) {
        b.validate();
        if (b.walk_key() != a.walk_key())
            throw InputError("trials in one group must share world, seed, protocol and robot");
    }
}

// The group's running state: everything a checkpoint saves.
struct GroupRun {
    const std::vector<TrialConfig>& trials;
    World world;
    std::vector<SensorUse> sensors;
    std::vector<int> sensor_of;
    std::vector<BoundaryVectorLayer> layers;
    std::vector<BoundaryVectorLayer::ScanPlan> plans;
    std::vector<PlaceCellNetwork> nets;
    std::vector<std::vector<double>> bvc_rates;
    RandomWalk walk;
    GroupResult result;
    std::int64_t step_index = 0;

    explicit GroupRun(const std::vector<TrialConfig>& t);
    void reserve_samples();
    void step(const WalkStep& s, bool learn, bool record);
    std::size_t ckpt_segments = 0, ckpt_saved = 0;  // samples already in checkpoint segments
    GroupCheckpoint checkpoint(const std::string& fingerprint) const;
    void restore(const GroupCheckpoint& c);
};

RandomWalk make_walk(const World& world, const TrialConfig& c) {
    auto body = std::make_shared<const BodyCollider>(world.description(), c.robot.radius, c.robot.height);
    Rng rng(c.seed, Stream::walk);
    const Pose start = RandomWalk::draw_start(world.description(), *body, rng);
    return RandomWalk(body, c.robot, std::move(rng), start);
}

GroupRun::GroupRun(const std::vector<TrialConfig>& t)
    : trials(t), world(t.front().world.resolve()), walk(make_walk(world, t.front())) {
    for (const auto& c : trials) {
        layers.emplace_back(c.model.bvc);
        nets.emplace_back(c.model.bvc.n_cells(), c.model.place, c.seed);
        bvc_rates.emplace_back(layers.back().n_cells());
        auto it = std::find_if(sensors.begin(), sensors.end(),
                               [&](const SensorUse& u) { return u.spec.same_beams(c.model.sensor); });
        if (it == sensors.end()) {
            sensors.push_back(SensorUse{c.model.sensor, Lidar(c.model.sensor),
                                        std::vector<char>(c.model.sensor.elevations.size(), 0), {}, {}, false});
            it = sensors.end() - 1;
        }
        const int si = static_cast<int>(it - sensors.begin());
        sensor_of.push_back(si);
        plans.push_back(layers.back().plan(c.model.sensor));
        for (std::size_t r = 0; r < plans.back().rows.size(); ++r) sensors[si].rows[r] |= plans.back().rows[r];
        ModelRecord rec;
        rec.n_place = c.model.place.n_place;
        rec.n_bvc = c.model.bvc.n_cells();
        result.models.push_back(std::move(rec));
    }
    // Room for the samples a full recording phase can hold (a model step takes model_dt of forward
    // motion), so growing buffers never double past it: with many models on one walk that matters.
    reserve_samples();
}

void GroupRun::reserve_samples() {
    const auto& first = trials.front();
    const auto expected = static_cast<std::size_t>(first.protocol.sample_hours * 3600.0 / first.robot.model_dt) + 64;
    for (auto* v : {&result.t, &result.x, &result.y, &result.heading}) v->reserve(expected);
    for (auto& rec : result.models) {
        rec.rates.reserve(expected * rec.n_place);
        if (first.protocol.record_bvc) rec.bvc.reserve(expected * rec.n_bvc);
    }
}

void GroupRun::step(const WalkStep& s, bool learn, bool record) {
    const Pose pose{s.x, s.y, s.heading};
    // Sensor noise: the trial's own stream, the same draws for every sensor of the group (common
    // random numbers: conditions that differ in their noise level see the same underlying draws).
    const NoiseKey noise{hash_u64(trials.front().seed, static_cast<std::uint64_t>(Stream::sensor_noise), 0),
                         static_cast<std::uint64_t>(step_index)};
    for (auto& u : sensors) {
        u.lidar.scan(world, pose, u.scan, noise, u.rows);
        u.full_cast = false;
    }
    for (std::size_t i = 0; i < layers.size(); ++i) {
        SensorUse& u = sensors[sensor_of[i]];
        if (!layers[i].rates_pruned(u.scan, plans[i], bvc_rates[i])) {
            // The pruning bound failed (almost nothing in view): every beam, the full sum.
            if (!u.full_cast) u.lidar.scan(world, pose, u.full, noise);
            u.full_cast = true;
            layers[i].rates(u.full, bvc_rates[i]);
            ++result.stats.full_scan_fallbacks;
        }
        const auto v = nets[i].step(bvc_rates[i], learn);
        if (record) {
            auto& rec = result.models[i];
            rec.rates.insert(rec.rates.end(), v.begin(), v.end());
            if (trials.front().protocol.record_bvc)
                for (double b : bvc_rates[i]) rec.bvc.push_back(static_cast<float>(b));
        }
    }
    if (record) {
        result.t.push_back(s.t);
        result.x.push_back(s.x);
        result.y.push_back(s.y);
        result.heading.push_back(s.heading);
    }
    ++step_index;
    result.stats.bumps += s.bumped;
    (record ? result.stats.sample_steps : result.stats.explore_steps) += 1;
}

GroupCheckpoint GroupRun::checkpoint(const std::string& fingerprint) const {
    // The state, and only the samples recorded since the last checkpoint.
    GroupCheckpoint c;
    c.fingerprint = fingerprint;
    c.walk = walk.state();
    c.step_index = step_index;
    c.segments = ckpt_segments;
    c.saved = ckpt_saved;
    c.partial.stats = result.stats;
    const auto from = static_cast<std::ptrdiff_t>(ckpt_saved);
    c.partial.t.assign(result.t.begin() + from, result.t.end());
    c.partial.x.assign(result.x.begin() + from, result.x.end());
    c.partial.y.assign(result.y.begin() + from, result.y.end());
    c.partial.heading.assign(result.heading.begin() + from, result.heading.end());
    for (std::size_t i = 0; i < nets.size(); ++i) {
        const auto& rec = result.models[i];
        ModelRecord m;
        m.n_place = rec.n_place;
        m.n_bvc = rec.n_bvc;
        m.rates.assign(rec.rates.begin() + from * rec.n_place, rec.rates.end());
        if (!rec.bvc.empty()) m.bvc.assign(rec.bvc.begin() + from * rec.n_bvc, rec.bvc.end());
        c.partial.models.push_back(std::move(m));
        c.partial.models[i].weights = nets[i].weights();
        c.membrane.emplace_back(nets[i].membrane().begin(), nets[i].membrane().end());
        c.place_rates.emplace_back(nets[i].rates().begin(), nets[i].rates().end());
    }
    return c;
}

void GroupRun::restore(const GroupCheckpoint& c) {
    if (c.partial.models.size() != nets.size()) throw InputError("checkpoint does not match the group");
    walk.restore(c.walk);
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
    GroupRun run(trials);
    const std::string fingerprint = group_fingerprint(trials);
    if (!control.checkpoint.empty() && std::filesystem::exists(control.checkpoint)) {
        const auto saved = read_checkpoint(control.checkpoint);
        if (saved && saved->fingerprint == fingerprint) run.restore(*saved);
    }
    const Protocol& p = trials.front().protocol;
    const bool online = p.kind == Protocol::Kind::online;
    const double t_explore = online ? 0.0 : p.explore_hours * 3600.0;
    const double t_end = t_explore + p.sample_hours * 3600.0;
    const double ckpt_every = control.checkpoint_minutes * 60.0;
    double next_ckpt = ckpt_every > 0 ? (std::floor(run.walk.time() / ckpt_every) + 1) * ckpt_every : INFINITY;

    for (std::int64_t n = 0;; ++n) {
        const bool sampling = run.walk.time() >= t_explore;
        const auto s = run.walk.next(sampling ? t_end : t_explore);
        if (!s) {
            if (sampling) break;
            continue;  // exploration is over: go on sampling from here
        }
        run.step(*s, !sampling || online, sampling);
        if (control.progress && n % 512 == 0) control.progress(run.walk.time(), run.step_index);
        const bool stop = control.stop && n % 64 == 0 && control.stop->load();
        if (!control.checkpoint.empty() && (stop || run.walk.time() >= next_ckpt)) {
            GroupCheckpoint c = run.checkpoint(fingerprint);
            write_checkpoint(control.checkpoint, c);
            run.ckpt_segments = c.segments;
            run.ckpt_saved = c.saved;
            while (next_ckpt <= run.walk.time()) next_ckpt += ckpt_every;
        }
        if (stop) throw Interrupted();
    }
    if (control.progress) control.progress(run.walk.time(), run.step_index);
    for (std::size_t i = 0; i < run.nets.size(); ++i) run.result.models[i].weights = run.nets[i].weights();
    run.result.stats.end_time = run.walk.time();
    return std::move(run.result);
}

}  // namespace bvc3d

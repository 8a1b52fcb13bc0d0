#include "bvc3d/experiment/trial_runner.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <span>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/experiment/model_network.hpp"
#include "bvc3d/recorder/checkpoint_file.hpp"

namespace bvc3d {

namespace {

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
    std::unique_ptr<Agent> agent;
    ModelNetwork models;  // every model's populations, stepped as the agent steps
    GroupResult result;   // the samples' poses and the walk's counts (the rates are in the network until the end)
    std::int64_t step_index = 0;
    std::int64_t fallbacks_before = 0;              // full-scan fallbacks of the run before a restored checkpoint
    std::size_t ckpt_segments = 0, ckpt_saved = 0;  // samples already in checkpoint segments
    std::size_t expected = 0;                       // samples a full recording phase holds

    GroupRun(const World* w, const std::vector<TrialConfig>& t, const SourceFactory& factory)
        : trials(t),
          agent(t.front().agent->make(w, t.front().seed)),
          models(w, t, factory, t.front().protocol.record_bvc) {
        // Room for the samples a full recording phase can hold, so growing buffers never double past it: with many
        // models on one agent that matters.
        const auto& first = trials.front();
        expected =
            static_cast<std::size_t>(first.protocol.sample_hours * 3600.0 * first.agent->steps_per_second()) + 64;
        reserve(expected);
    }
    void reserve(std::size_t samples) {
        for (auto* v : {&result.t, &result.x, &result.y, &result.z, &result.heading}) v->reserve(samples);
        models.network.reserve(samples);
    }
    void step(const ModelStep& s, bool learn, bool record) {
        models.network.step(s, step_index, learn, record);
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
    std::int64_t fallbacks() const {
        for (const auto& [name, count] : models.network.counters())
            if (name == "full_scan_fallbacks") return fallbacks_before + count;
        return fallbacks_before;
    }
    GroupCheckpoint checkpoint(const std::string& fingerprint);
    void restore(const GroupCheckpoint& c);
    GroupResult finish(bool keep_states);
};

GroupCheckpoint GroupRun::checkpoint(const std::string& fingerprint) {
    // The state, and only the samples recorded since the last checkpoint.
    GroupCheckpoint c;
    c.fingerprint = fingerprint;
    c.agent_state = agent->save_state();
    c.step_index = step_index;
    c.segments = ckpt_segments;
    c.saved = ckpt_saved;
    c.states = models.network.state();  // flushes the steps waiting
    c.partial.stats = result.stats;
    c.partial.stats.full_scan_fallbacks = fallbacks();
    const auto from = static_cast<std::ptrdiff_t>(ckpt_saved);
    for (auto [to, all] :
         {std::pair{&c.partial.t, &result.t}, std::pair{&c.partial.x, &result.x}, std::pair{&c.partial.y, &result.y},
          std::pair{&c.partial.z, &result.z}, std::pair{&c.partial.heading, &result.heading}})
        to->assign(all->begin() + from, all->end());
    c.partial.models = models.records(ckpt_saved);
    return c;
}

void GroupRun::restore(const GroupCheckpoint& c) {
    // A checkpoint that does not fit throws InputError; the caller then starts from a new GroupRun.
    models.restore(c.partial.models, c.states);
    agent->restore_state(c.agent_state);
    step_index = c.step_index;
    ckpt_segments = c.segments;
    ckpt_saved = c.saved;
    result.t = c.partial.t;
    result.x = c.partial.x;
    result.y = c.partial.y;
    result.z = c.partial.z;
    result.heading = c.partial.heading;
    result.stats = c.partial.stats;
    fallbacks_before = c.partial.stats.full_scan_fallbacks;
    reserve(expected);
}

GroupResult GroupRun::finish(bool keep_states) {
    models.network.flush();
    result.stats.full_scan_fallbacks = fallbacks();
    result.stats.end_time = agent->time();
    result.stats.agent_report = agent->report();
    if (keep_states) result.states = models.network.state();
    result.models = models.records(0, true);
    return std::move(result);
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
    const SourceFactory factory = sources || !returns ? sources : returns->factory(trials.front().seed);
    auto run = std::make_unique<GroupRun>(world, trials, factory);
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
                run->restore(*saved.checkpoint);
            } catch (const InputError& e) {
                warn("checkpoint '" + control.checkpoint.string() + "' does not fit this trial (" + e.what() +
                     "); the trial starts again from the beginning");
                run = std::make_unique<GroupRun>(world, trials, factory);
            }
        }
    }
    const Protocol& p = trials.front().protocol;
    const bool online = p.kind == Protocol::Kind::online;
    const double t_explore = online ? 0.0 : p.explore_hours * 3600.0;
    const double t_end = t_explore + (p.records() ? p.sample_hours * 3600.0 : 0.0);
    const double ckpt_every = control.checkpoint_minutes * 60.0;
    double next_ckpt = ckpt_every > 0 ? (std::floor(run->agent->time() / ckpt_every) + 1) * ckpt_every : INFINITY;

    for (std::int64_t n = 0;; ++n) {
        const bool sampling = run->agent->time() >= t_explore;
        const auto s = run->agent->next(sampling ? t_end : t_explore);
        if (!s) {
            if (sampling || (!p.records() && run->agent->finished())) break;
            if (run->agent->finished())
                throw InputError(
                    "the agent's path ends after " + format_number(run->agent->time() / 3600) +
                    " h, before the recorded phase begins (explore_hours = " + format_number(p.explore_hours) + ")");
            continue;  // exploration is over: go on sampling from here
        }
        run->step(*s, !sampling || online, sampling);
        if (control.progress && n % std::max<std::int64_t>(1, control.progress_every) == 0)
            control.progress(run->agent->time(), run->step_index);
        const bool stop = control.stop && n % 64 == 0 && control.stop->load();
        if (!control.checkpoint.empty() && (stop || run->agent->time() >= next_ckpt)) {
            GroupCheckpoint c = run->checkpoint(fingerprint);
            write_checkpoint(control.checkpoint, c);
            run->ckpt_segments = c.segments;
            run->ckpt_saved = c.saved;
            while (next_ckpt <= run->agent->time()) next_ckpt += ckpt_every;
        }
        if (stop) throw Interrupted();
    }
    // A learning run that others go on from (navigation) keeps its end as a checkpoint: an interrupt after it resumes
    // there.
    if (!control.checkpoint.empty() && control.checkpoint_at_end) {
        GroupCheckpoint c = run->checkpoint(fingerprint);
        write_checkpoint(control.checkpoint, c);
    }
    GroupResult result = run->finish(control.keep_states);
    if (control.progress) control.progress(run->agent->time(), run->step_index);
    return result;
}

}  // namespace bvc3d

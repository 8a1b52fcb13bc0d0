#include "bvc3d/experiment/experiment.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <mutex>
#include <set>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/parallel.hpp"
#include "bvc3d/experiment/pipeline.hpp"

namespace bvc3d {

namespace {

using Clock = std::chrono::steady_clock;

struct Group {
    std::vector<std::size_t> members;  // indices into the trial list
    std::string key;
};

// Trials that share world, seed, protocol and robot run on one walk.
std::vector<Group> make_groups(const std::vector<TrialConfig>& trials, const std::vector<std::size_t>& todo) {
    std::map<std::string, Group> by_key;
    std::vector<std::string> order;
    for (std::size_t i : todo) {
        const auto& t = trials[i];
        const std::string key = t.walk_key();
        if (!by_key.count(key)) order.push_back(key);
        by_key[key].members.push_back(i);
    }
    std::vector<Group> groups;
    for (const auto& k : order) {
        Group g = by_key[k];
        const auto& first = trials[g.members.front()];
        g.key = first.world.label() + "_seed" + std::to_string(first.seed) + "_" + first.fingerprint();
        groups.push_back(std::move(g));
    }
    return groups;
}

// Progress: trials done, simulated hours, steps per second, time left. On a terminal one line
// rewritten in place; otherwise a line per finished trial and per tenth of the simulated time.
class Progress {
public:
    Progress(ProgressStyle style, int total_trials, double total_seconds)
        : style_(style), total_trials_(total_trials), total_seconds_(total_seconds), start_(Clock::now()) {}
    void add(double seconds, std::int64_t walk_steps, std::int64_t models) {
        seconds_.fetch_add(seconds);
        live_model_steps_.fetch_add(walk_steps * models);
    }
    void add_steps(std::int64_t n, std::int64_t models) {
        steps_.fetch_add(n);
        model_steps_.fetch_add(n * models);
    }
    std::int64_t steps() const { return steps_.load(); }
    std::int64_t model_steps() const { return model_steps_.load(); }
    void trial_done(const std::string& name) {
        trials_.fetch_add(1);
        if (style_ == ProgressStyle::lines) line(name);
    }
    // From the thread that waits for the workers, every fraction of a second.
    void tick() {
        if (style_ == ProgressStyle::terminal) {
            terminal(false);
        } else if (style_ == ProgressStyle::lines && total_seconds_ > 0) {
            const int tenth = static_cast<int>(10 * seconds_.load() / total_seconds_);
            if (tenth > printed_tenth_ && tenth < 10) {
                printed_tenth_ = tenth;
                line("");
            }
        }
    }
    void finish() {
        if (style_ == ProgressStyle::terminal) terminal(true);
        else if (style_ == ProgressStyle::lines && total_trials_ > 0) line("done");
    }

private:
    double wall() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }
    std::string left() const {
        const double done = seconds_.load();
        if (!(done > 0)) return "?";
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.0f", wall() * std::max(0.0, total_seconds_ - done) / done);
        return buf;
    }
    void terminal(bool final) {
        std::lock_guard lock(mutex_);
        const double w = wall();
        std::fprintf(stderr, "\r  %d/%d trials  %.1f/%.1f simulated hours  %.0f model steps/s  %s%s s       %s",
                     trials_.load(), total_trials_, seconds_.load() / 3600, total_seconds_ / 3600,
                     w > 0 ? static_cast<double>(live_model_steps_.load()) / w : 0.0, final ? "took " : "~",
                     final ? std::to_string(static_cast<long long>(w + 0.5)).c_str() : left().c_str(),
                     final ? "\n" : "");
        std::fflush(stderr);
    }
    // "bvc3d: 3/16 trials done (cross-30_2d_seed0), 0.40/1.60 simulated hours (25%), ~95 s left"
    void line(const std::string& what) {
        std::lock_guard lock(mutex_);
        const double done = std::min(seconds_.load(), total_seconds_);
        std::string text =
            "bvc3d: " + std::to_string(trials_.load()) + "/" + std::to_string(total_trials_) + " trials done";
        if (!what.empty() && what != "done") text += " (" + what + ")";
        char buf[160];
        if (what == "done") {
            std::snprintf(buf, sizeof buf, ", %.2f simulated hours in %.0f s", total_seconds_ / 3600, wall());
        } else {
            std::snprintf(buf, sizeof buf, ", %.2f/%.2f simulated hours (%.0f%%), ~%s s left", done / 3600,
                          total_seconds_ / 3600, total_seconds_ > 0 ? 100 * done / total_seconds_ : 100.0,
                          left().c_str());
        }
        std::fprintf(stderr, "%s%s\n", text.c_str(), buf);
        std::fflush(stderr);
    }

    ProgressStyle style_;
    int total_trials_;
    double total_seconds_;
    Clock::time_point start_;
    std::atomic<double> seconds_{0};
    std::atomic<std::int64_t> steps_{0}, model_steps_{0}, live_model_steps_{0};
    std::atomic<int> trials_{0};
    int printed_tenth_ = 0;  // the waiting thread's
    std::mutex mutex_;
};

// What a trial's model holds beyond its BVC layer and place cells: every population of ModelSpec::populations (their
// footprints, resolved in order: each reads only those before it), and the fused scales of a multiscale model.
struct ModelFootprint {
    double recorded_cells = 0;    // floats per recorded sample
    double state_bytes = 0;       // weights and the like
    double largest_analysed = 0;  // cells of the largest population analysed (the fused scales count as one)
};

ModelFootprint model_footprint(const ModelSpec& model, bool record_bvc) {
    std::map<std::string, std::size_t> cells{{"bvc", model.bvc.n_cells()},
                                             {"place", static_cast<std::size_t>(model.place.n_place)}};
    std::set<std::string> recorded{"place"};
    ModelFootprint f;
    f.recorded_cells = model.place.n_place + (record_bvc ? model.bvc.n_cells() : 0);
    f.largest_analysed = model.place.n_place;
    for (const PopulationSpec& spec : model.populations) {
        std::vector<std::size_t> in;
        for (const auto& name : spec.inputs) in.push_back(cells.count(name) ? cells.at(name) : 0);
        const PopulationFootprint p = spec.footprint ? spec.footprint(in) : PopulationFootprint{};
        cells[spec.name] = p.cells;
        f.state_bytes += p.state_bytes;
        if (!spec.recorded) continue;
        recorded.insert(spec.name);
        f.recorded_cells += static_cast<double>(p.cells);
        f.largest_analysed = std::max(f.largest_analysed, static_cast<double>(p.cells));
    }
    if (!model.place_grid.empty()) f.state_bytes += 4.0 * model.place.n_place * cells[model.place_grid];
    // The recorded scales of place cells, fused as the analysis fuses them (pipeline.cpp): one more population.
    double fused = 0;
    std::size_t n_fused = 0;
    for (const std::string& name : model.place_scales())
        if (recorded.count(name)) fused += static_cast<double>(cells.at(name)), ++n_fused;
    if (n_fused > 1) {
        f.recorded_cells += fused;
        f.largest_analysed = std::max(f.largest_analysed, fused);
    }
    return f;
}

// The peak memory of one group of trials sharing an agent.
double group_memory(const std::vector<const TrialConfig*>& group) {
    const TrialConfig& first = *group.front();
    const double samples = first.protocol.sample_hours * 3600.0 * first.agent->steps_per_second() + 64;
    double bytes = samples * 5 * sizeof(double);  // t, x, y, z, heading
    double largest_trial = 0;
    for (const auto* t : group) {
        const double n_place = t->model.place.n_place, n_bvc = t->model.bvc.n_cells();
        const ModelFootprint more = model_footprint(t->model, t->protocol.record_bvc);
        const double gridsize = t->analysis.gridsize;
        const double bins = std::min(samples, 1.2 * gridsize * gridsize);  // hexagons visited, at most
        const double recorded = samples * more.recorded_cells * sizeof(float);
        const double weights = n_place * n_bvc * sizeof(float) + more.state_bytes;
        // One population analysed at a time: its maps and a copy of its rates in double.
        const double analysis =
            4 * bins * more.largest_analysed * sizeof(double) + samples * more.largest_analysed * sizeof(double) / 8;
        const double scan = static_cast<double>(t->model.sensor.beam_count()) * 3 * sizeof(double);
        bytes += recorded + 3 * weights + scan;
        largest_trial = std::max(largest_trial, analysis + recorded + weights);  // analyzed and written one at a time
    }
    // A checkpoint copies the samples since the last one; a trial file is built in memory first.
    return bytes + largest_trial + samples * 5 * sizeof(double) + 64e6;
}

}  // namespace

std::filesystem::path trial_path(const std::filesystem::path& out_dir, const TrialConfig& t) {
    return out_dir / (t.name() + ".h5");
}

double estimate_memory(const std::vector<TrialConfig>& trials, int jobs) {
    std::map<std::string, std::vector<const TrialConfig*>> groups;
    for (const auto& t : trials) groups[t.walk_key()].push_back(&t);
    std::vector<double> sizes;
    for (const auto& [key, group] : groups) sizes.push_back(group_memory(group));
    std::sort(sizes.begin(), sizes.end(), std::greater<>());
    const std::size_t threads = thread_count(jobs);
    double total = 0;
    for (std::size_t i = 0; i < std::min(threads, sizes.size()); ++i) total += sizes[i];
    return total;
}

namespace {

class LocalCoordinator : public Coordinator {
public:
    explicit LocalCoordinator(std::size_t n) : n_(n) {}
    std::vector<std::size_t> agree(std::vector<std::size_t> pending) override {
        n_ = pending.size();
        return pending;
    }
    std::optional<std::size_t> next() override {
        const std::size_t i = next_.fetch_add(1);
        return i < n_ ? std::optional<std::size_t>(i) : std::nullopt;
    }

private:
    std::size_t n_;
    std::atomic<std::size_t> next_{0};
};

// One call of run_experiment: the trials, their files and groups, and what the workers share.
class ExperimentRun {
public:
    ExperimentRun(const std::vector<TrialConfig>& trials, const ExperimentOptions& options, Coordinator& coord)
        : trials_(trials), options_(options), coord_(coord), ckpt_dir_(options.out_dir / ".checkpoints") {}
    ExperimentOutcome run();

private:
    void check_trials() const;
    bool complete(std::size_t i) const { return trial_file_complete(files_[i], trials_[i]); }
    std::vector<std::size_t> unfinished_groups(int& complete_before) const;
    void run_group(const Group& g, const std::atomic<bool>* stop);
    void work();

    const std::vector<TrialConfig>& trials_;
    const ExperimentOptions& options_;
    Coordinator& coord_;
    std::filesystem::path ckpt_dir_;
    std::vector<std::filesystem::path> files_;
    std::vector<Group> groups_;
    std::vector<std::size_t> pending_;  // indices into groups_, as the root dealt them
    std::unique_ptr<Progress> progress_;
    std::atomic<int> ran_{0};
};

void ExperimentRun::check_trials() const {
    std::set<std::string> names;
    for (const auto& t : trials_)
        if (!names.insert(t.name()).second) throw InputError("two trials would share the file name '" + t.name() + "'");
    check_runnable(trials_);  // fail early on bad worlds, start points and robots
    ensure_writable_directory(options_.out_dir);
}

// Groups with at least one trial whose file is not complete (the root's view).
std::vector<std::size_t> ExperimentRun::unfinished_groups(int& complete_before) const {
    std::vector<std::size_t> pending;
    for (std::size_t g = 0; g < groups_.size(); ++g) {
        bool any = false;
        for (std::size_t i : groups_[g].members) {
            const bool done = complete(i);
            complete_before += done;
            any = any || !done;
        }
        if (any) pending.push_back(g);
    }
    return pending;
}

void ExperimentRun::run_group(const Group& g, const std::atomic<bool>* stop) {
    // Only the members whose files are missing run; they still share the agent.
    std::vector<TrialConfig> members;
    std::vector<std::filesystem::path> paths;
    for (std::size_t i : g.members)
        if (!complete(i)) {
            members.push_back(trials_[i]);
            paths.push_back(files_[i]);
        }
    if (members.empty()) return;
    RunControl control;
    control.stop = stop;
    control.checkpoint = ckpt_dir_ / (g.key + ".h5");
    control.checkpoint_minutes = options_.checkpoint_minutes;
    double last = 0;
    std::int64_t last_steps = 0;
    const auto n_models = static_cast<std::int64_t>(members.size());
    control.progress = [&](double t, std::int64_t steps) {
        progress_->add(t - last, steps - last_steps, n_models);
        last = t;
        last_steps = steps;
    };
    const GroupOutcome done = run_analyze_write(members, paths, control);
    for (const auto& m : members) {
        if (options_.on_trial_done) options_.on_trial_done(m.name());
        progress_->trial_done(m.name());
        ++ran_;
    }
    progress_->add_steps(done.result.stats.explore_steps + done.result.stats.sample_steps, n_models);
}

// A worker: groups from the coordinator until none is left, or until the pool is cancelled (Ctrl-C or
// another worker's error). Only the trial runner stops a group, checkpointing first: an analysis under
// way finishes and its file is written.
void ExperimentRun::work() {
    const std::atomic<bool>* stop = cancel_flag();  // the pool's
    for (;;) {
        if (stop->load()) throw Interrupted();
        const auto g = coord_.next();
        if (!g) return;
        const CancelScope only_the_runner(nullptr);
        run_group(groups_[pending_[*g]], stop);
    }
}

ExperimentOutcome ExperimentRun::run() {
    const auto start = Clock::now();
    check_trials();
    ExperimentOutcome outcome;
    std::vector<std::size_t> all(trials_.size());
    for (std::size_t i = 0; i < trials_.size(); ++i) {
        all[i] = i;
        files_.push_back(trial_path(options_.out_dir, trials_[i]));
    }
    outcome.files = files_;
    // Groups of trials that share an agent; the root decides which still have work.
    groups_ = make_groups(trials_, all);
    int complete_before = 0;
    pending_ = coord_.agree(coord_.is_root() ? unfinished_groups(complete_before) : std::vector<std::size_t>{});
    double total_seconds = 0;
    int todo_trials = 0;
    for (std::size_t g : pending_) {
        total_seconds += trials_[groups_[g].members.front()].protocol.seconds();
        todo_trials += static_cast<int>(groups_[g].members.size());
    }
    if (!pending_.empty()) ensure_writable_directory(ckpt_dir_);
    progress_ = std::make_unique<Progress>(coord_.is_root() ? options_.progress : ProgressStyle::none, todo_trials,
                                           total_seconds);
    {
        // Ctrl-C (options_.stop) or the first error stops every worker; more threads than groups would only wait.
        const CancelScope scope(options_.stop ? options_.stop : cancel_flag());
        ParallelOptions parallel;
        parallel.tick = [this] { progress_->tick(); };
        const std::size_t threads = std::min(thread_count(options_.jobs), std::max<std::size_t>(pending_.size(), 1));
        try {
            run_workers(
                threads, [this](std::size_t) { work(); }, parallel);
        } catch (...) {
            coord_.finish();
            throw;
        }
        coord_.finish();
    }
    progress_->finish();
    std::error_code ec;
    std::filesystem::remove(ckpt_dir_, ec);  // only if empty
    outcome.skipped = complete_before;
    outcome.ran = coord_.is_root() ? static_cast<int>(trials_.size()) - complete_before : ran_.load();
    outcome.steps = progress_->steps();
    outcome.model_steps = progress_->model_steps();
    outcome.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return outcome;
}

}  // namespace

ExperimentOutcome run_experiment(const std::vector<TrialConfig>& trials, const ExperimentOptions& options,
                                 Coordinator* coordinator) {
    LocalCoordinator local(0);
    return ExperimentRun(trials, options, coordinator ? *coordinator : local).run();
}

}  // namespace bvc3d

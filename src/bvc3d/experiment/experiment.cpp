#include "bvc3d/experiment/experiment.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
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

// The progress line: trials done, simulated hours, steps per second, time left.
class Progress {
public:
    Progress(bool on, int total_trials, double total_seconds)
        : on_(on), total_trials_(total_trials), total_seconds_(total_seconds), start_(Clock::now()) {}
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
    void trial_done() { trials_.fetch_add(1); }
    void print(bool final = false) {
        if (!on_) return;
        std::lock_guard lock(mutex_);
        const double wall = std::chrono::duration<double>(Clock::now() - start_).count();
        const double done = seconds_.load();
        char left[32] = "?";
        if (final || done > 0) std::snprintf(left, sizeof left, "%.0f", final ? wall : wall * (total_seconds_ - done) / done);
        std::fprintf(stderr, "\r  %d/%d trials  %.1f/%.1f simulated hours  %.0f model steps/s  %s%s s       %s",
                     trials_.load(), total_trials_, done / 3600, total_seconds_ / 3600,
                     wall > 0 ? static_cast<double>(live_model_steps_.load()) / wall : 0.0, final ? "took " : "~", left,
                     final ? "\n" : "");
        std::fflush(stderr);
    }

private:
    bool on_;
    int total_trials_;
    double total_seconds_;
    Clock::time_point start_;
    std::atomic<double> seconds_{0};
    std::atomic<std::int64_t> steps_{0}, model_steps_{0}, live_model_steps_{0};
    std::atomic<int> trials_{0};
    std::mutex mutex_;
};

}  // namespace

std::filesystem::path trial_path(const std::filesystem::path& out_dir, const TrialConfig& t) {
    return out_dir / (t.name() + ".h5");
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

}  // namespace

ExperimentOutcome run_experiment(const std::vector<TrialConfig>& trials, const ExperimentOptions& options,
                                 Coordinator* coordinator) {
    const auto start = Clock::now();
    LocalCoordinator local(0);
    Coordinator& coord = coordinator ? *coordinator : local;
    ExperimentOutcome outcome;
    std::set<std::string> names;
    for (const auto& t : trials) {
        if (!names.insert(t.name()).second) throw InputError("two trials would share the file name '" + t.name() + "'");
        t.validate();
        t.world.resolve();  // fail early on bad worlds
    }
    ensure_writable_directory(options.out_dir);
    const auto ckpt_dir = options.out_dir / ".checkpoints";

    // Groups of trials that share a walk; the root decides which still have work.
    std::vector<std::size_t> all(trials.size());
    for (std::size_t i = 0; i < trials.size(); ++i) {
        all[i] = i;
        outcome.files.push_back(trial_path(options.out_dir, trials[i]));
    }
    const auto groups = make_groups(trials, all);
    auto complete = [&](std::size_t i) { return trial_file_complete(outcome.files[i], trials[i]); };
    std::vector<std::size_t> pending;
    int complete_before = 0;
    if (coord.is_root())
        for (std::size_t g = 0; g < groups.size(); ++g) {
            bool any = false;
            for (std::size_t i : groups[g].members) {
                const bool done = complete(i);
                complete_before += done;
                any = any || !done;
            }
            if (any) pending.push_back(g);
        }
    pending = coord.agree(pending);
    double total_seconds = 0;
    int todo_trials = 0;
    for (std::size_t g : pending) {
        total_seconds += trials[groups[g].members.front()].protocol.seconds();
        todo_trials += static_cast<int>(groups[g].members.size());
    }
    if (!pending.empty()) ensure_writable_directory(ckpt_dir);

    Progress progress(options.progress && coord.is_root(), todo_trials, total_seconds);
    std::atomic<bool> interrupted{false}, failed{false}, stop_all{false};
    std::atomic<int> ran{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    // Stop everything on Ctrl-C or on the first error.
    std::jthread watcher([&](std::stop_token st) {
        while (!st.stop_requested()) {
            if ((options.stop && options.stop->load()) || failed.load()) stop_all = true;
            progress.print();
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
        }
    });

    auto run_group = [&](const Group& g) {
        // Only the members whose files are missing run; they still share the agent.
        std::vector<TrialConfig> members;
        std::vector<std::filesystem::path> paths;
        for (std::size_t i : g.members)
            if (!complete(i)) {
                members.push_back(trials[i]);
                paths.push_back(outcome.files[i]);
            }
        if (members.empty()) return;
        RunControl control;
        control.stop = &stop_all;
        control.checkpoint = ckpt_dir / (g.key + ".h5");
        control.checkpoint_minutes = options.checkpoint_minutes;
        double last = 0;
        std::int64_t last_steps = 0;
        const auto n_models = static_cast<std::int64_t>(members.size());
        control.progress = [&](double t, std::int64_t steps) {
            progress.add(t - last, steps - last_steps, n_models);
            last = t;
            last_steps = steps;
        };
        const GroupOutcome done = run_analyze_write(members, paths, control);
        for (const auto& m : members) {
            if (options.on_trial_done) options.on_trial_done(m.name());
            progress.trial_done();
            ++ran;
        }
        const auto& stats = done.result.stats;
        progress.add_steps(stats.explore_steps + stats.sample_steps, static_cast<std::int64_t>(members.size()));
    };
    auto worker = [&] {
        while (!stop_all.load()) {
            const auto g = coord.next();
            if (!g) return;
            try {
                run_group(groups[pending[*g]]);
            } catch (const Interrupted&) {
                interrupted = true;
            } catch (...) {
                std::lock_guard lock(error_mutex);
                if (!error) error = std::current_exception();
                failed = true;
            }
        }
        if (stop_all.load()) interrupted = true;
    };
    const int jobs = options.jobs > 0 ? options.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    {
        std::vector<std::jthread> workers;
        for (int j = 0; j < jobs; ++j) workers.emplace_back(worker);
    }
    coord.finish();
    watcher.request_stop();
    watcher.join();
    if (error) std::rethrow_exception(error);
    if (interrupted && !failed) throw Interrupted();
    progress.print(true);
    std::error_code ec;
    std::filesystem::remove(ckpt_dir, ec);  // only if empty
    outcome.skipped = complete_before;
    outcome.ran = coord.is_root() ? static_cast<int>(trials.size()) - complete_before : ran.load();
    outcome.steps = progress.steps();
    outcome.model_steps = progress.model_steps();
    outcome.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return outcome;
}

}  // namespace bvc3d

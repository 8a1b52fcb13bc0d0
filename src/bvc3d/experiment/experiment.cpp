#include "bvc3d/experiment/experiment.hpp"

#include <tbb/parallel_for_each.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/trial_runner.hpp"
#include "bvc3d/recorder/trial_file.hpp"

namespace bvc3d {

namespace {

using Clock = std::chrono::steady_clock;

struct Group {
    std::vector<std::size_t> members;  // indices into the trial list
    std::string key;
};

// Trials that share world, seed and protocol run on one walk.
std::vector<Group> make_groups(const std::vector<TrialConfig>& trials, const std::vector<std::size_t>& todo) {
    std::map<std::string, Group> by_key;
    std::vector<std::string> order;
    for (std::size_t i : todo) {
        const auto& t = trials[i];
        const std::string key = t.world.label() + "_seed" + std::to_string(t.seed) + "_" +
                                protocol_name(t.protocol.kind) + "_" + std::to_string(t.protocol.explore_hours) + "_" +
                                std::to_string(t.protocol.sample_hours) + (t.protocol.record_bvc ? "_bvc" : "") + "_" +
                                t.world.fingerprint();
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
    void add_seconds(double s) { seconds_.fetch_add(s); }
    void add_steps(std::int64_t n) { steps_.fetch_add(n); }
    std::int64_t steps() const { return steps_.load(); }
    void trial_done() { trials_.fetch_add(1); }
    void print(bool final = false) {
        if (!on_) return;
        std::lock_guard lock(mutex_);
        const double wall = std::chrono::duration<double>(Clock::now() - start_).count();
        const double done = seconds_.load();
        const double left = done > 0 ? wall * (total_seconds_ - done) / done : 0;
        std::fprintf(stderr, "\r  %d/%d trials  %.1f/%.1f simulated hours  %.0f steps/s  %s%.0f s       %s",
                     trials_.load(), total_trials_, done / 3600, total_seconds_ / 3600,
                     wall > 0 ? static_cast<double>(steps_.load()) / wall : 0.0, final ? "took " : "~", final ? wall : left,
                     final ? "\n" : "");
        std::fflush(stderr);
    }

private:
    bool on_;
    int total_trials_;
    double total_seconds_;
    Clock::time_point start_;
    std::atomic<double> seconds_{0};
    std::atomic<std::int64_t> steps_{0};
    std::atomic<int> trials_{0};
    std::mutex mutex_;
};

}  // namespace

std::filesystem::path trial_path(const std::filesystem::path& out_dir, const TrialConfig& t) {
    return out_dir / (t.name() + ".h5");
}

analysis::TrialMetrics analyze(const TrialConfig& t, const WorldDescription& world, const std::vector<double>& x,
                               const std::vector<double>& y, const std::vector<float>& rates, int n_place) {
    analysis::AnalysisParams params = t.analysis;
    if (t.arena_extent) {
        const auto box = world.walkable.bounds();
        params.extent = analysis::Extent{box.min().x(), box.max().x(), box.min().y(), box.max().y()};
    }
    const Eigen::Map<const analysis::RowMatrixXf> r(rates.data(), static_cast<Eigen::Index>(x.size()), n_place);
    return analysis::analyze_trial<float>(x, y, r, params);
}

ExperimentOutcome run_experiment(const std::vector<TrialConfig>& trials, const ExperimentOptions& options) {
    const auto start = Clock::now();
    ExperimentOutcome outcome;
    std::set<std::string> names;
    for (const auto& t : trials) {
        if (!names.insert(t.name()).second) throw InputError("two trials would share the file name '" + t.name() + "'");
        t.model.validate();
        t.protocol.validate();
        t.analysis.validate();
        t.world.resolve();  // fail early on bad worlds
    }
    ensure_writable_directory(options.out_dir);
    const auto ckpt_dir = options.out_dir / ".checkpoints";

    std::vector<std::size_t> todo;
    double total_seconds = 0;
    for (std::size_t i = 0; i < trials.size(); ++i) {
        const auto path = trial_path(options.out_dir, trials[i]);
        outcome.files.push_back(path);
        if (trial_file_fingerprint(path) == trials[i].fingerprint()) {
            ++outcome.skipped;
        } else {
            todo.push_back(i);
        }
    }
    const auto groups = make_groups(trials, todo);
    for (const auto& g : groups) {
        const auto& p = trials[g.members.front()].protocol;
        total_seconds += 3600 * (p.kind == Protocol::Kind::online ? p.sample_hours : p.explore_hours + p.sample_hours);
    }
    if (!groups.empty()) ensure_writable_directory(ckpt_dir);

    Progress progress(options.progress, static_cast<int>(todo.size()), total_seconds);
    std::atomic<bool> interrupted{false};
    std::exception_ptr error;
    std::mutex error_mutex;
    std::atomic<bool> failed{false};
    // Stop everything on Ctrl-C or on the first error.
    std::atomic<bool> stop_all{false};
    std::jthread watcher([&](std::stop_token st) {
        while (!st.stop_requested()) {
            if ((options.stop && options.stop->load()) || failed.load()) stop_all = true;
            progress.print();
            std::this_thread::sleep_for(std::chrono::milliseconds(200));
        }
    });

    const int jobs = options.jobs > 0 ? options.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    tbb::task_arena arena(jobs);
    arena.execute([&] {
        tbb::parallel_for_each(groups.begin(), groups.end(), [&](const Group& g) {
            if (stop_all.load()) {
                interrupted = true;
                return;
            }
            std::vector<TrialConfig> members;
            for (std::size_t i : g.members) members.push_back(trials[i]);
            RunControl control;
            control.stop = &stop_all;
            control.checkpoint = ckpt_dir / (g.key + ".h5");
            control.checkpoint_minutes = options.checkpoint_minutes;
            double last = 0;
            control.progress = [&](double t) {
                progress.add_seconds(t - last);
                last = t;
            };
            try {
                const GroupResult result = run_trial_group(members, control);
                const WorldDescription world = members.front().world.resolve();
                for (std::size_t k = 0; k < members.size(); ++k) {
                    const auto metrics = analyze(members[k], world, result.x, result.y, result.models[k].rates,
                                                 result.models[k].n_place);
                    write_trial_file(trial_path(options.out_dir, members[k]), members[k], result, k, metrics);
                    progress.trial_done();
                }
                progress.add_steps(result.stats.explore_steps + result.stats.sample_steps);
                std::error_code ec;
                std::filesystem::remove(control.checkpoint, ec);
            } catch (const Interrupted&) {
                interrupted = true;
            } catch (...) {
                std::lock_guard lock(error_mutex);
                if (!error) error = std::current_exception();
                failed = true;
            }
        });
    });
    watcher.request_stop();
    watcher.join();
    if (error) std::rethrow_exception(error);
    if (interrupted) throw Interrupted();
    progress.print(true);
    std::error_code ec;
    std::filesystem::remove(ckpt_dir, ec);  // only if empty
    outcome.ran = static_cast<int>(todo.size());
    outcome.steps = progress.steps();
    outcome.wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return outcome;
}

}  // namespace bvc3d

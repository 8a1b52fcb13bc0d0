#include "run_options.hpp"

#include <algorithm>
#include <cstdio>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/memory.hpp"
#include "bvc3d/recorder/trial_file.hpp"
#include "cli_common.hpp"
#include "summary_report.hpp"

namespace bvc3d::cli {

const char* const no_memory_check_help = "Run even when the estimated memory exceeds what the machine has available";

CLI::Option* RunOptions::add_out(CLI::App& cmd, const std::string& help, OutputKind kind,
                                 std::vector<std::string> own) {
    return outputs.add(cmd, "--out", out, kind, help, std::move(own));
}

CLI::Option* RunOptions::add_jobs(CLI::App& cmd, const std::string& what, const std::string& note) {
    return add_jobs_option(cmd, jobs, what, note);
}

CLI::Option* RunOptions::add_checkpoint_minutes(CLI::App& cmd) {
    return cmd
        .add_option("--checkpoint-minutes", checkpoint_minutes,
                    "Checkpoint every this many simulated minutes (0: only on Ctrl-C)")
        ->capture_default_str();
}

CLI::Option* RunOptions::add_no_memory_check(CLI::App& cmd) {
    return cmd.add_flag("--no-memory-check", no_memory_check, no_memory_check_help);
}

CLI::Option* RunOptions::add_no_figures(CLI::App& cmd, const std::string& what) {
    return add_no_figures_option(cmd, no_figures, what);
}

void RunOptions::add_experiment_options(CLI::App& cmd, const std::string& out_help) {
    add_out(cmd, out_help, OutputKind::results_folder);
    add_jobs(cmd);
    add_checkpoint_minutes(cmd);
    add_no_figures(cmd, "the figures and report.md");
    add_no_memory_check(cmd);
}

void RunOptions::check() const {
    check_jobs(jobs);
    if (!(checkpoint_minutes >= 0)) throw InputError("--checkpoint-minutes must be >= 0");
    outputs.check();
}

void RunOptions::check_memory(const std::vector<TrialConfig>& trials, int threads) const {
    if (no_memory_check) return;
    const std::string what =
        trials.size() == 1 ? "this trial" : "this run (" + std::to_string(trials.size()) + " trials)";
    bvc3d::check_memory(
        estimate_memory(trials, threads), what,
        "shorten sample_hours, use fewer --jobs or smaller models, or pass --no-memory-check to try anyway");
}

std::string output_folder_text(const std::filesystem::path& folder) {
    return "output folder '" + folder.string() + "'";
}

OutputLock lock_output_folder(const std::filesystem::path& path) {
    const auto folder = without_trailing_slash(path);
    const auto created = ensure_writable_directory(folder);
    try {
        return OutputLock(folder_lock_path(folder), output_folder_text(folder), folder, created);
    } catch (...) {
        remove_empty_folders(folder, created);
        throw;
    }
}

OutputLock lock_output_file(const std::filesystem::path& path) {
    const auto file = without_trailing_slash(path);
    require_not_directory(file, "--out");
    const auto parent = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
    const auto created = ensure_writable_directory(parent);
    try {
        return OutputLock(file_lock_path(file), "trial file '" + file.string() + "'", parent, created);
    } catch (...) {
        remove_empty_folders(parent, created);
        throw;
    }
}

void print_outcome(std::size_t n_trials, const std::filesystem::path& out, const ExperimentOutcome& outcome) {
    std::printf("%zu trials in %s (%d run, %d already complete) in %.1f s", n_trials, out.c_str(), outcome.ran,
                outcome.skipped, outcome.wall_seconds);
    if (outcome.steps > 0)
        std::printf(", %.0f walk steps/s, %.0f model steps/s", outcome.steps / outcome.wall_seconds,
                    outcome.model_steps / outcome.wall_seconds);
    std::printf("\n");
}

void check_folder_holds_one_kind(const std::filesystem::path& out, const std::vector<TrialConfig>& trials) {
    std::error_code ec;
    if (trials.empty() || !std::filesystem::is_directory(out, ec)) return;
    const bool navigating = trials.front().navigation != nullptr;
    const auto kind = [](bool navigation) {
        return navigation ? std::string("navigation trials") : std::string("trials that record place cells");
    };
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(out))
        if (e.path().extension() == ".h5") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
        const auto stamp = read_trial_stamp(f);
        if (stamp && stamp->navigation != navigating)
            throw InputError(output_folder_text(out) + " holds files of another kind (first: '" +
                             f.filename().string() + "', of " + kind(stamp->navigation) + "): " + kind(navigating) +
                             " go to another --out (one folder's tables cannot hold both)");
    }
}

ExperimentOutcome run_experiment_in_folder(const std::vector<TrialConfig>& trials, const RunOptions& o,
                                           const FolderRunHooks& hooks) {
    o.check();  // before anything is written
    check_folder_holds_one_kind(o.out, trials);
    check_runnable(trials);
    o.check_memory(trials, o.jobs);
    const OutputLock lock = lock_output_folder(o.out);
    if (hooks.under_lock) hooks.under_lock();
    ExperimentOptions opts;
    opts.out_dir = o.out;
    opts.jobs = o.jobs;
    opts.progress = progress_style();
    opts.checkpoint_minutes = o.checkpoint_minutes;
    opts.stop = &stop_flag();
    opts.on_trial_done = hooks.on_trial_done;
    ExperimentOutcome outcome;
    {
        InterruptGuard guard;
        try {
            outcome = run_experiment(trials, opts);
        } catch (const Interrupted&) {
            exit_interrupted();
        }
    }
    print_outcome(trials.size(), o.out, outcome);
    summarize(o.out, outcome.files, !o.no_figures);
    return outcome;
}

}  // namespace bvc3d::cli

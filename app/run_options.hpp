#pragma once
// What the commands that run trials share, written once: the options --out (with --force), --jobs,
// --checkpoint-minutes, --no-memory-check and --no-figures with their help and checks, the output's
// lock (one writer per folder or trial file, core/output_lock.hpp), the memory check, and an
// experiment's whole run into a folder (paper, flight, a local sweep): trials on this machine's
// threads, the outcome line, the tables and the figures.
// Takes: a command's parsed options and its trials. Gives: locks, trial files, summaries, figures.
#include <CLI/CLI.hpp>

#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/core/output_lock.hpp"
#include "bvc3d/experiment/experiment.hpp"
#include "option_groups.hpp"

namespace bvc3d::cli {

extern const char* const no_memory_check_help;

struct RunOptions {
    std::string out;  // an output folder, or a trial file (`run`, `replay`); set a default before add_out
    int jobs = 0;
    double checkpoint_minutes = 0;  // simulated minutes between checkpoints; 0: only on Ctrl-C
    bool no_memory_check = false;
    bool no_figures = false;
    Outputs outputs{};  // --out and --force

    // Each adds its option to `cmd` (from the option groups, option_groups.hpp); a non-empty `out` and
    // checkpoint_minutes show as defaults. A results folder is resumed when it holds one of `own`.
    CLI::Option* add_out(CLI::App& cmd, const std::string& help, OutputKind kind,
                         std::vector<std::string> own = experiment_folder_marks());
    CLI::Option* add_jobs(CLI::App& cmd, const std::string& what = "Trials", const std::string& note = "");
    CLI::Option* add_checkpoint_minutes(CLI::App& cmd);
    CLI::Option* add_no_memory_check(CLI::App& cmd);
    CLI::Option* add_no_figures(CLI::App& cmd, const std::string& what = "the figures");
    // The experiments' block (paper, flight, sweep): all five, --out a results folder.
    void add_experiment_options(CLI::App& cmd, const std::string& out_help = "Output folder");

    // --jobs (0 .. max_jobs), --checkpoint-minutes (>= 0) and the outputs (the rule for existing ones),
    // or InputError naming the option.
    void check() const;
    // Refuses (InputError) trials whose estimated memory on `jobs` threads (0: one per core)
    // exceeds what the machine has available, unless --no-memory-check.
    void check_memory(const std::vector<TrialConfig>& trials, int jobs) const;
};

// "output folder 'DIR'": how messages (and the lock's holder message) name an output folder.
std::string output_folder_text(const std::filesystem::path& folder);
// The lock of an output folder, which is created (and must be writable) first; InputError naming
// the holder when another process has it.
OutputLock lock_output_folder(const std::filesystem::path& folder);
// The lock of a single output file (`--out` must not name a folder; its folder is created).
OutputLock lock_output_file(const std::filesystem::path& file);

// "N trials in DIR (R run, S already complete) in T s, ... steps/s".
void print_outcome(std::size_t n_trials, const std::filesystem::path& out, const ExperimentOutcome& outcome);

// What an experiment adds to its run: work under the folder's lock before the trials start (a
// sweep copies its file in), and a call for every finished trial (from worker threads).
struct FolderRunHooks {
    std::function<void()> under_lock;
    std::function<void(const std::string&)> on_trial_done;
};

// InputError when the folder `out` already holds complete trial files of the other kind than `trials` (navigation
// trials beside trials that record place cells): one folder's tables cannot hold both, and --force does not change
// that. Nothing when it does not exist or holds no trial file.
void check_folder_holds_one_kind(const std::filesystem::path& out, const std::vector<TrialConfig>& trials);

// An experiment's run into the folder `o.out`: the options, the trials and the memory they need checked
// before anything is written, the folder locked, the trials run on this machine's threads with
// progress on standard error (Ctrl-C or SIGTERM checkpoints and exits with status 130), the
// outcome line printed, trials.csv and summary.csv/.md written and, unless --no-figures, the figures.
ExperimentOutcome run_experiment_in_folder(const std::vector<TrialConfig>& trials, const RunOptions& o,
                                           const FolderRunHooks& hooks = {});

}  // namespace bvc3d::cli

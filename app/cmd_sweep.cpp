// bvc3d sweep: a grid of conditions × seeds, on local threads or over MPI ranks (mpirun).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <mutex>
#include <optional>
#include <sstream>

#include "bvc3d/config/sweep_yaml.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/output_lock.hpp"
#include "bvc3d/experiment/experiment.hpp"
#include "bvc3d/experiment/trial_runner.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "run_options.hpp"
#include "summary_report.hpp"
#ifdef BVC3D_HAVE_MPI
#include "bvc3d/experiment/mpi_coordinator.hpp"
#endif

namespace bvc3d::cli {

namespace {

// Launched by mpirun/srun? (Checked without initializing MPI, which a plain run must not need.)
bool launched_by_mpi() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
        if (std::getenv(v)) return true;
    return false;
}

void copy_sweep_file(const std::string& from, const std::filesystem::path& dir) {
    std::ifstream in(from, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    AtomicFile out(dir / "sweep.yaml");
    out.write(text.str());
    out.commit();
}

struct SweepOptions {
    std::string file;
    std::optional<double> hours;
    bool dry_run = false, verbose = false;
    RunOptions run;  // --out (default results/<sweep name>), --jobs, ...
};

// The sweep's trials with the command line's overrides; the options checked.
config::Sweep checked_sweep(const SweepOptions& o) {
    auto sweep = config::load_sweep_file(o.file);
    if (o.hours) {
        if (!(*o.hours > 0) || !std::isfinite(*o.hours)) throw InputError("--hours must be a positive number of hours");
        for (auto& t : sweep.trials) t.protocol.explore_hours = t.protocol.sample_hours = *o.hours;
    }
    o.run.check();
    return sweep;
}

// "rank R: TRIAL" for every finished trial, one line at a time.
std::function<void(const std::string&)> trial_printer(bool verbose, const int& rank) {
    if (!verbose) return {};
    auto print = std::make_shared<std::mutex>();
    return [print, &rank](const std::string& name) {
        std::lock_guard lock(*print);
        std::printf("rank %d: %s\n", rank, name.c_str());
        std::fflush(stdout);
    };
}

#ifdef BVC3D_HAVE_MPI
// Under mpirun: rank 0 deals groups of trials to the ranks. Returns false on ranks other than 0.
bool run_over_mpi(const config::Sweep& sweep, const SweepOptions& o, const std::filesystem::path& out,
                  ExperimentOutcome& outcome) {
    const int jobs = o.run.jobs == 0 ? 1 : o.run.jobs;
    o.run.check_memory(sweep.trials, jobs);  // per rank
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
    if (provided < MPI_THREAD_SERIALIZED) {
        std::cerr << "bvc3d: the MPI library does not support MPI_THREAD_SERIALIZED\n";
        MPI_Abort(MPI_COMM_WORLD, 3);
    }
    InterruptGuard guard;
    MpiCoordinator coord(MPI_COMM_WORLD, &stop_flag());
    const int rank = coord.rank();
    ExperimentOptions opts;
    opts.out_dir = out;
    opts.jobs = jobs;
    opts.checkpoint_minutes = o.run.checkpoint_minutes;
    opts.stop = &stop_flag();
    opts.progress = progress_style();
    opts.on_trial_done = trial_printer(o.verbose, rank);
    std::optional<OutputLock> lock;
    try {
        if (coord.is_root()) {
            lock.emplace(folder_lock_path(out), output_folder_text(out));
            copy_sweep_file(o.file, out);
        }
        outcome = run_experiment(sweep.trials, opts, &coord);
    } catch (const Interrupted&) {
        MPI_Finalize();
        exit_interrupted();
    } catch (const std::exception& e) {
        std::cerr << "bvc3d: error on rank " << rank << ": " << e.what() << "\n";
        MPI_Abort(MPI_COMM_WORLD, 2);
    }
    MPI_Finalize();
    return rank == 0;
}
#endif

}  // namespace

void add_sweep_command(CLI::App& app) {
    auto* cmd = app.add_subcommand("sweep", "Run a parameter sweep (conditions x seeds) on local cores or over MPI");
    auto o = std::make_shared<SweepOptions>();
    cmd->add_option("sweep", o->file, "Sweep YAML file (docs/sweeps.md)")->required();
    o->run.add_out(*cmd, "Output folder (default results/<sweep name>)", OutputKind::results_folder);
    o->run.add_jobs(*cmd, "Trials", " (under mpirun: per rank, and 0 is 1)");
    o->run.add_checkpoint_minutes(*cmd);
    o->run.add_no_figures(*cmd, "the figures and report.md");
    o->run.add_no_memory_check(*cmd);
    cmd->add_option("--hours", o->hours, "Shorten both phases of every trial to H simulated hours");
    cmd->add_flag("--dry-run", o->dry_run, "List the trials and exit");
    cmd->add_flag("--verbose", o->verbose, "Print a line for every finished trial (with its MPI rank)");
    cmd->footer(
        "Under `mpirun -np N bvc3d sweep FILE`, rank 0 deals trials to the ranks as they become free; the output\n"
        "folder must be shared by all ranks. Completed trials are skipped on a rerun. See docs/cluster.md.");
    cmd->callback([o] {
        const auto sweep = checked_sweep(*o);
        RunOptions& run = o->run;
        if (run.out.empty()) run.out = (std::filesystem::path("results") / sweep.name).string();
        const std::filesystem::path out = run.out;
        if (!o->dry_run) run.outputs.check();  // the default's too
        if (o->dry_run) {
            check_runnable(sweep.trials);
            for (const auto& t : sweep.trials) std::printf("%s\n", t.name().c_str());
            std::printf("%zu trials\n", sweep.trials.size());
            return;
        }
#ifdef BVC3D_HAVE_MPI
        if (launched_by_mpi()) {
            check_runnable(sweep.trials);  // before MPI starts
            ensure_writable_directory(out);
            ExperimentOutcome outcome;
            if (!run_over_mpi(sweep, *o, out, outcome)) return;
            print_outcome(sweep.trials.size(), out, outcome);  // rank 0; the ranks have finished
            summarize(out, outcome.files, !run.no_figures);
            std::printf("summary: %s/summary.md\n", out.c_str());
            return;
        } else
#else
        if (launched_by_mpi())
            throw InputError(
                "this bvc3d was built without MPI, so under mpirun every rank would run every trial: "
                "rebuild with MPI (libopenmpi-dev) or run `bvc3d sweep` without mpirun");
#endif
        {
            static const int rank = 0;
            run_experiment_in_folder(sweep.trials, run,
                                     {[&] { copy_sweep_file(o->file, out); }, trial_printer(o->verbose, rank)});
            std::printf("summary: %s/summary.md\n", out.c_str());
        }
    });
}

}  // namespace bvc3d::cli

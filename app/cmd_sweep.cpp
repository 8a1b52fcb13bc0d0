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
    std::string file, out;
    std::optional<double> hours;
    int jobs = 0;
    double checkpoint_minutes = 0;
    bool no_report = false, dry_run = false, verbose = false, no_memory_check = false;
};

// The sweep's trials with the command line's overrides, checked before anything runs (and before MPI starts).
config::Sweep checked_sweep(const SweepOptions& o) {
    auto sweep = config::load_sweep_file(o.file);
    if (o.hours) {
        if (!(*o.hours > 0) || !std::isfinite(*o.hours)) throw InputError("--hours must be a positive number of hours");
        for (auto& t : sweep.trials) t.protocol.explore_hours = t.protocol.sample_hours = *o.hours;
    }
    check_jobs(o.jobs);
    if (o.checkpoint_minutes < 0) throw InputError("--checkpoint-minutes must be >= 0");
    check_runnable(sweep.trials);
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
    check_run_memory(sweep.trials, o.jobs == 0 ? 1 : o.jobs, o.no_memory_check);  // per rank
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
    opts.jobs = o.jobs == 0 ? 1 : o.jobs;
    opts.checkpoint_minutes = o.checkpoint_minutes;
    opts.stop = &stop_flag();
    opts.progress = progress_style();
    opts.on_trial_done = trial_printer(o.verbose, rank);
    std::optional<OutputLock> lock;
    try {
        if (coord.is_root()) {
            lock.emplace(folder_lock_path(out), "output folder '" + out.string() + "'");
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
    cmd->add_option("--out", o->out, "Output folder (default results/<sweep name>)");
    cmd->add_option("--hours", o->hours, "Shorten both phases of every trial to H simulated hours");
    cmd->add_option("--jobs", o->jobs,
                    "Threads (per rank under MPI); 0 (the default): one per core, or 1 per rank under MPI");
    cmd->add_option("--checkpoint-minutes", o->checkpoint_minutes,
                    "Checkpoint running trials every M simulated minutes");
    cmd->add_flag("--no-report", o->no_report, "Skip the figures");
    cmd->add_flag("--dry-run", o->dry_run, "List the trials and exit");
    cmd->add_flag("--verbose", o->verbose, "Print a line for every finished trial (with its MPI rank)");
    cmd->add_flag("--no-memory-check", o->no_memory_check, no_memory_check_help);
    cmd->footer(
        "Under `mpirun -np N bvc3d sweep FILE`, rank 0 deals trials to the ranks as they become free; the output\n"
        "folder must be shared by all ranks. Completed trials are skipped on a rerun. See docs/cluster.md.");
    cmd->callback([o] {
        const auto sweep = checked_sweep(*o);
        const std::filesystem::path out =
            o->out.empty() ? std::filesystem::path("results") / sweep.name : std::filesystem::path(o->out);
        if (o->dry_run) {
            for (const auto& t : sweep.trials) std::printf("%s\n", t.name().c_str());
            std::printf("%zu trials\n", sweep.trials.size());
            return;
        }
        ensure_writable_directory(out);
        ExperimentOutcome outcome;
#ifdef BVC3D_HAVE_MPI
        if (launched_by_mpi()) {
            if (!run_over_mpi(sweep, *o, out, outcome)) return;
            print_outcome(sweep.trials.size(), out, outcome);  // rank 0; the ranks have finished
            summarize(out, outcome.files, !o->no_report);
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
            const OutputLock lock(folder_lock_path(out), "output folder '" + out.string() + "'");
            copy_sweep_file(o->file, out);
            static const int rank = 0;
            outcome = run_local_experiment(
                sweep.trials, out,
                LocalRun{o->jobs, o->checkpoint_minutes, o->no_memory_check, trial_printer(o->verbose, rank)});
            print_outcome(sweep.trials.size(), out, outcome);
            summarize(out, outcome.files, !o->no_report);
            std::printf("summary: %s/summary.md\n", out.c_str());
        }
    });
}

}  // namespace bvc3d::cli

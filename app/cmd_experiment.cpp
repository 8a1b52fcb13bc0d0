// bvc3d run / paper / analyze: trials, the paper's experiment, and analysis of trial files.
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <sstream>

#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/analysis/metrics.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/trial_yaml.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/experiment.hpp"
#include "bvc3d/experiment/pipeline.hpp"
#include "bvc3d/report/summary.hpp"
#include "cli_common.hpp"

namespace bvc3d::cli {

namespace {

// Ctrl-C (SIGINT) or SIGTERM (mpirun passing on a Ctrl-C, a batch system's time limit) asks running
// trials to checkpoint and stop; a second signal ends the program at once.
extern "C" void on_stop_signal(int sig) {
    stop_flag().store(true);
    std::signal(sig, SIG_DFL);
}

std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    for (std::string item; std::getline(ss, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

// Text as one shell word: as it is when safe, else single-quoted.
std::string shell_word(const std::string& s) {
    const bool safe = !s.empty() && s.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789"
                                                         "_-./:=+,@%") == std::string::npos;
    if (safe) return s;
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

// How the report module runs: the interpreter (BVC3D_PYTHON, else the one found at build time) and
// the PYTHONPATH that finds the package (BVC3D_PYTHONPATH, else the build's python folder, then any
// PYTHONPATH already set).
struct ReportCommand {
    std::string python, pythonpath;
    // The command as a shell line that works as printed: `PYTHONPATH=... /usr/bin/python3 -m bvc3d.report DIR`.
    std::string shell_line(const std::filesystem::path& dir) const {
        return "PYTHONPATH=" + shell_word(pythonpath) + " " + shell_word(python) + " -m bvc3d.report " +
               shell_word(dir.string());
    }
};

ReportCommand report_command() {
    const char* py_env = std::getenv("BVC3D_PYTHON");
    const char* path_env = std::getenv("BVC3D_PYTHONPATH");
    ReportCommand c{py_env && *py_env ? py_env : BVC3D_PYTHON, path_env && *path_env ? path_env : BVC3D_PYTHON_DIR};
    if (const char* existing = std::getenv("PYTHONPATH"); existing && *existing && c.pythonpath != existing)
        c.pythonpath += std::string(":") + existing;
    return c;
}

// Runs the report module as a child process (no shell); returns its exit status.
int run_report(const ReportCommand& command, const std::filesystem::path& dir) {
    std::fflush(stdout);  // our lines first, then the report's
    const pid_t pid = ::fork();
    if (pid < 0) return -1;
    if (pid == 0) {
        ::setenv("PYTHONPATH", command.pythonpath.c_str(), 1);
        ::execl(command.python.c_str(), command.python.c_str(), "-m", "bvc3d.report", dir.c_str(),
                static_cast<char*>(nullptr));
        std::perror(("bvc3d: cannot run " + command.python).c_str());
        ::_exit(127);
    }
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

std::atomic<bool>& stop_flag() {
    static std::atomic<bool> stop{false};  // set from the SIGINT handler
    return stop;
}

InterruptGuard::InterruptGuard() {
    std::signal(SIGINT, on_stop_signal);
    std::signal(SIGTERM, on_stop_signal);
}
InterruptGuard::~InterruptGuard() {
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
}

void exit_interrupted() {
    std::cerr << "\nbvc3d: interrupted; finished trials are kept. Run the same command again to resume.\n";
    std::exit(130);
}

ExperimentOutcome run_local_experiment(const std::vector<TrialConfig>& trials, const std::filesystem::path& out,
                                       int jobs, double checkpoint_minutes, std::function<void(const std::string&)> on_done) {
    if (jobs < 0) throw InputError("--jobs must be >= 0");
    if (checkpoint_minutes < 0) throw InputError("--checkpoint-minutes must be >= 0");
    ExperimentOptions opts;
    opts.out_dir = out;
    opts.jobs = jobs;
    opts.progress = ::isatty(STDERR_FILENO);
    opts.checkpoint_minutes = checkpoint_minutes;
    opts.stop = &stop_flag();
    opts.on_trial_done = std::move(on_done);
    InterruptGuard guard;
    try {
        return run_experiment(trials, opts);
    } catch (const Interrupted&) {
        exit_interrupted();
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

void summarize(const std::filesystem::path& out, const std::vector<std::filesystem::path>& files, bool report) {
    const auto trials = read_summaries(files);
    const auto rows = summarize(trials);
    write_trials_csv(out / "trials.csv", trials);
    write_summary_csv(out / "summary.csv", rows);
    write_summary_markdown(out / "summary.md", rows);
    if (!report) return;
    const ReportCommand command = report_command();
    if (run_report(command, out) != 0)
        throw InputError("the report (figures) failed; the trial files and summary are in '" + out.string() +
                         "'; rerun it with:\n  " + command.shell_line(out));
}

namespace {

struct RunOptions {
    std::string config, world, lean, model, protocol, extent, out, trajectory;
    std::optional<double> tilt, explore_hours, sample_hours, hours;
    std::optional<std::uint64_t> seed;
    bool record_bvc = false;
    double checkpoint_minutes = 10;
};

// The trial `bvc3d run` runs: the YAML file's, with the flags on top.
TrialConfig run_config(const RunOptions& o) {
    TrialConfig t = o.config.empty() ? TrialConfig{} : config::load_trial_file(o.config);
    if (!o.world.empty()) t.world = WorldSpec{o.world, std::nullopt, "+x+y"};
    if (o.tilt) t.world.tilt_deg = o.tilt;
    if (!o.lean.empty()) t.world.lean = o.lean;
    if (!o.model.empty()) t.model = config::resolve_model(o.model);
    if (!o.trajectory.empty()) t.agent = std::make_shared<TrajectorySpec>(TrajectorySpec::from_file(o.trajectory));
    if (o.seed) t.seed = *o.seed;
    if (!o.protocol.empty()) t.protocol.kind = parse_protocol(o.protocol);
    if (o.hours) t.protocol.explore_hours = t.protocol.sample_hours = *o.hours;
    if (o.explore_hours) t.protocol.explore_hours = *o.explore_hours;
    if (o.sample_hours) t.protocol.sample_hours = *o.sample_hours;
    if (o.record_bvc) t.protocol.record_bvc = true;
    if (!o.extent.empty()) {
        if (o.extent != "data" && o.extent != "arena") throw InputError("--extent must be 'data' or 'arena'");
        t.arena_extent = o.extent == "arena";
    }
    if (o.checkpoint_minutes < 0) throw InputError("--checkpoint-minutes must be >= 0");
    t.validate();
    t.world.resolve();  // fail early on bad worlds
    return t;
}

// Runs one trial into `out` through the trial pipeline, with a progress line on a terminal.
void run_one(const TrialConfig& t, const std::filesystem::path& out, double checkpoint_minutes) {
    const bool tty = ::isatty(STDERR_FILENO);
    const double total = t.protocol.seconds();
    InterruptGuard guard;
    RunControl control;
    control.stop = &stop_flag();
    control.checkpoint = out.string() + ".ckpt";
    control.checkpoint_minutes = checkpoint_minutes;
    const auto start = std::chrono::steady_clock::now();
    if (tty)
        control.progress = [&](double s, std::int64_t) {
            const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            std::fprintf(stderr, "\r  %.2f/%.2f simulated hours  ~%.0f s left   ", s / 3600, total / 3600,
                         s > 0 ? wall * (total - s) / s : 0.0);
        };
    GroupOutcome done;
    try {
        done = run_analyze_write({t}, {out}, control);
    } catch (const Interrupted&) {
        exit_interrupted();
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (tty) std::fprintf(stderr, "\n");
    const auto& r = done.result;
    std::printf("wrote %s: %zu samples, %.0f steps/s\n", out.c_str(), r.t.size(),
                (r.stats.explore_steps + r.stats.sample_steps) / wall);
    for (const auto& [name, v] : analysis::scalar_metrics(done.trials[0].metrics)) std::printf("  %-16s %g\n", name.c_str(), v);
}

void add_run(CLI::App& app) {
    auto* cmd = app.add_subcommand("run", "Run one trial and write its HDF5 file");
    auto o = std::make_shared<RunOptions>();
    cmd->add_option("--config", o->config, "Trial YAML file (docs/experiments.md); flags below override it");
    cmd->add_option("--world", o->world, "World preset or YAML file (default cross)");
    cmd->add_option("--tilt", o->tilt, "Tilt of the cross arena's walls, degrees");
    cmd->add_option("--lean", o->lean, "Corner the cross walls lean toward (default +x+y)");
    cmd->add_option("--model", o->model, "Model preset or model YAML (default 3d-0.2)");
    cmd->add_option("--trajectory", o->trajectory,
                    "Follow this path instead of the random walk: a text file of t, x, y, [z], heading rows");
    cmd->add_option("--seed", o->seed, "Random seed (default 0)")->check(seed_check);
    cmd->add_option("--protocol", o->protocol, "explore_then_sample (the paper's, default) or online");
    cmd->add_option("--explore-hours", o->explore_hours, "Simulated hours of exploration (learning on)");
    cmd->add_option("--sample-hours", o->sample_hours, "Simulated hours of sampling (recorded)");
    cmd->add_option("--hours", o->hours, "Shorten both phases to this many simulated hours");
    cmd->add_flag("--record-bvc", o->record_bvc, "Also record the BVC rates");
    cmd->add_option("--extent", o->extent, "Rate-map grid over the 'data' (default) or the 'arena'");
    cmd->add_option("--out", o->out, "Trial file to write (default results/<trial name>.h5)");
    cmd->add_option("--checkpoint-minutes", o->checkpoint_minutes,
                    "Checkpoint every this many simulated minutes (0: only on Ctrl-C)")
        ->capture_default_str();
    cmd->footer("Ctrl-C checkpoints and stops; running the same command again resumes and gives the same file.");
    cmd->callback([o] {
        const TrialConfig t = run_config(*o);
        const std::filesystem::path out = o->out.empty() ? std::filesystem::path("results") / (t.name() + ".h5")
                                                         : std::filesystem::path(o->out);
        ensure_writable_directory(out.has_parent_path() ? out.parent_path() : ".");
        if (trial_file_complete(out, t)) {
            std::cerr << "bvc3d: " << out.string() << " is complete with this configuration; nothing to do\n";
            return;
        }
        run_one(t, out, o->checkpoint_minutes);
    });
}

struct PaperOptions {
    std::string out = "results/paper", models = "2d,3d-0.1,3d-0.2,3d-3l", tilts = "0,30,45,60", protocol;
    int seeds = 1, jobs = 0;
    std::optional<double> hours;
    double checkpoint_minutes = 0;
    bool no_report = false, arena_extent = false;
};

// Models × tilts × seeds, seeds slowest.
std::vector<TrialConfig> paper_trials(const PaperOptions& o) {
    if (o.seeds < 1) throw InputError("--seeds must be >= 1");
    if (o.hours && !(*o.hours > 0)) throw InputError("--hours must be a positive number of hours");
    std::vector<ModelSpec> models;
    for (const auto& m : split(o.models)) models.push_back(config::resolve_model(m));
    if (models.empty()) throw InputError("--models lists no model");
    std::vector<double> tilts;
    for (const auto& t : split(o.tilts)) tilts.push_back(parse_number(t, "--tilts: a tilt"));
    if (tilts.empty()) throw InputError("--tilts lists no tilt");
    std::vector<TrialConfig> trials;
    for (int seed = 0; seed < o.seeds; ++seed)
        for (double tilt : tilts)
            for (const auto& m : models) {
                TrialConfig t;
                t.world = WorldSpec{"cross", tilt, "+x+y"};
                t.model = m;
                t.seed = static_cast<std::uint64_t>(seed);
                if (!o.protocol.empty()) t.protocol.kind = parse_protocol(o.protocol);
                if (o.hours) t.protocol.explore_hours = t.protocol.sample_hours = *o.hours;
                t.arena_extent = o.arena_extent;
                trials.push_back(t);
            }
    return trials;
}

void add_paper(CLI::App& app) {
    auto* cmd = app.add_subcommand("paper", "Run the paper's experiment: models x tilted worlds x seeds, summary, figures");
    auto o = std::make_shared<PaperOptions>();
    cmd->add_option("--out", o->out, "Output folder")->capture_default_str();
    cmd->add_option("--seeds", o->seeds, "Seeds per condition (0 .. N-1)")->capture_default_str();
    cmd->add_option("--hours", o->hours, "Shorten both phases to H simulated hours (default: the paper's 4 + 4)");
    cmd->add_option("--jobs", o->jobs, "Trials in parallel (default: every core)");
    cmd->add_option("--models", o->models, "Comma-separated model presets or model YAML files")->capture_default_str();
    cmd->add_option("--tilts", o->tilts, "Comma-separated tilts of the cross arena, degrees")->capture_default_str();
    cmd->add_option("--protocol", o->protocol, "explore_then_sample (default) or online");
    cmd->add_flag("--arena-extent", o->arena_extent, "Bin rate maps over the arena instead of each trajectory");
    cmd->add_option("--checkpoint-minutes", o->checkpoint_minutes,
                    "Checkpoint running trials every this many simulated minutes (0: only on Ctrl-C)");
    cmd->add_flag("--no-report", o->no_report, "Skip the figures (trial files and summary only)");
    cmd->footer(
        "Writes one HDF5 file per trial, trials.csv, summary.csv, summary.md, and the figures and report.md (the\n"
        "Python module bvc3d.report, run with " BVC3D_PYTHON " or $BVC3D_PYTHON). Completed trials are skipped on\n"
        "a rerun; Ctrl-C stops cleanly and can be resumed.");
    cmd->callback([o] {
        const auto trials = paper_trials(*o);
        const ExperimentOutcome outcome = run_local_experiment(trials, o->out, o->jobs, o->checkpoint_minutes);
        print_outcome(trials.size(), o->out, outcome);
        summarize(o->out, outcome.files, !o->no_report);
        std::printf("summary: %s/summary.md%s\n", o->out.c_str(), o->no_report ? "" : (", report: " + o->out + "/report.md").c_str());
    });
}

void add_analyze(CLI::App& app) {
    auto* cmd = app.add_subcommand("analyze", "Recompute the metrics of trial files, optionally with other parameters");
    struct Options {
        std::vector<std::string> files;
        std::optional<int> gridsize, min_samples;
        std::optional<double> quantile, eps, d_th;
        std::string extent, cells, templates;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("files", o->files, "Trial files (.h5)")->required();
    cmd->add_option("--gridsize", o->gridsize, "Hexagons across x");
    cmd->add_option("--quantile", o->quantile, "Rate-map threshold quantile");
    cmd->add_option("--eps", o->eps, "DBSCAN radius, m");
    cmd->add_option("--min-samples", o->min_samples, "DBSCAN min_samples");
    cmd->add_option("--d-th", o->d_th, "SAI exclusion distance, m");
    cmd->add_option("--extent", o->extent, "Grid extent XMIN,XMAX,YMIN,YMAX, or 'data' for the trajectory's own");
    cmd->add_option("--decoding-templates", o->templates,
                    "Decoder templates: rate_maps (thresholded, normalized maps; the default) or means (raw mean rates)");
    cmd->add_option("--cells", o->cells, "Write per-cell metrics of the first file to this CSV");
    cmd->footer("Each file is analyzed with the parameters its metrics were computed with; the options change only\n"
                "what they name (defaults: gridsize 50, quantile 0.1, eps 1, min-samples 20, d-th 2,\n"
                "decoding templates rate_maps; docs/analysis.md).");
    cmd->callback([o] {
        std::optional<analysis::Extent> extent;
        if (!o->extent.empty() && o->extent != "data") {
            const auto parts = split(o->extent);
            if (parts.size() != 4) throw InputError("--extent expects XMIN,XMAX,YMIN,YMAX or 'data'");
            extent = analysis::Extent{parse_number(parts[0], "--extent: a bound"), parse_number(parts[1], "--extent: a bound"),
                                      parse_number(parts[2], "--extent: a bound"), parse_number(parts[3], "--extent: a bound")};
        }
        std::vector<TrialFileData> trials;
        for (const auto& f : o->files) trials.push_back(read_trial_samples(f));  // all readable before any output
        std::printf("%-40s", "trial");
        for (const auto& n : analysis::metric_names()) std::printf(" %15s", n.c_str());
        std::printf("\n");
        for (std::size_t i = 0; i < trials.size(); ++i) {
            const auto& d = trials[i];
            analysis::AnalysisParams params = stored_analysis_params(d);
            if (o->gridsize) params.gridsize = *o->gridsize;
            if (o->quantile) params.quantile = *o->quantile;
            if (o->eps) params.dbscan.eps = *o->eps;
            if (o->min_samples) params.dbscan.min_samples = *o->min_samples;
            if (o->d_th) params.d_th = *o->d_th;
            if (!o->templates.empty()) params.decoding_templates = analysis::parse_decoding_templates(o->templates);
            if (o->extent == "data") params.extent.reset();
            if (extent) params.extent = extent;
            params.validate();
            const Eigen::Map<const analysis::RowMatrixXf> rates(d.rates.data(), static_cast<Eigen::Index>(d.x.size()),
                                                                static_cast<Eigen::Index>(d.n_place));
            const auto m = analysis::analyze_trial<float>(d.x, d.y, rates, params);
            std::printf("%-40s", d.name.c_str());
            for (const auto& [name, v] : analysis::scalar_metrics(m)) std::printf(" %15.6g", v);
            std::printf("\n");
            if (i == 0 && !o->cells.empty()) {
                AtomicFile f(o->cells);
                f.stream() << "cell,modality,peak_rate,mean_rate,field_area,spatial_info\n";
                for (std::size_t c = 0; c < m.modality.size(); ++c)
                    f.stream() << c << ',' << m.modality[c] << ',' << num(m.cells.peak_rate[c]) << ','
                               << num(m.cells.mean_rate[c]) << ',' << num(m.cells.field_area[c]) << ','
                               << num(m.cells.spatial_info[c]) << '\n';
                f.commit();
            }
        }
    });
}

void add_summarize(CLI::App& app) {
    auto* cmd = app.add_subcommand("summarize", "Write trials.csv, summary.csv/.md and the figures for a folder of trial files");
    auto dir = std::make_shared<std::string>();
    auto no_report = std::make_shared<bool>(false);
    cmd->add_option("folder", *dir, "Folder of trial files")->required();
    cmd->add_flag("--no-report", *no_report, "Skip the figures");
    cmd->callback([dir, no_report] {
        std::vector<std::filesystem::path> files;
        std::error_code ec;
        if (!std::filesystem::is_directory(*dir, ec)) throw InputError("'" + *dir + "' is not a folder");
        for (const auto& e : std::filesystem::directory_iterator(*dir))
            if (e.path().extension() == ".h5" && read_trial_stamp(e.path())) files.push_back(e.path());
        if (files.empty()) throw InputError("'" + *dir + "' holds no complete trial files");
        std::sort(files.begin(), files.end());
        summarize(*dir, files, !*no_report);
        std::printf("%zu trials summarized in %s/summary.md\n", files.size(), dir->c_str());
    });
}

}  // namespace

void add_experiment_commands(CLI::App& app) {
    add_run(app);
    add_paper(app);
    add_analyze(app);
    add_summarize(app);
}

}  // namespace bvc3d::cli

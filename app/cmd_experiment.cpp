// bvc3d run / paper / analyze / summarize: trials, the paper's experiment, and analysis of trial files.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/analysis/metrics.hpp"
#include "bvc3d/config/agent_kinds.hpp"
#include "bvc3d/config/authors.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/protocols.hpp"
#include "bvc3d/config/sweep_yaml.hpp"
#include "bvc3d/config/trial_yaml.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/csv.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/output_lock.hpp"
#include "bvc3d/experiment/experiment.hpp"
#include "bvc3d/experiment/pipeline.hpp"
#include "bvc3d/report/summary.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "option_groups.hpp"
#include "run_options.hpp"
#include "summary_report.hpp"
#include "table_options.hpp"

namespace bvc3d::cli {

namespace {

struct TrialOptions {
    std::string config, model, protocol, extent, trajectory, agent;
    WorldOptions world;
    std::optional<double> explore_hours, sample_hours, hours;
    std::optional<std::uint64_t> seed;
    bool record_bvc = false, step_per_row = false;
    RunOptions run;  // --out: the trial file; --checkpoint-minutes; --no-memory-check
};

// The trial `bvc3d run` runs: the YAML file's, with the flags on top.
TrialConfig run_config(const TrialOptions& o) {
    TrialConfig t = o.config.empty() ? TrialConfig{} : config::load_trial_file(o.config);
    t.world = o.world.over(t.world);
    if (!o.model.empty()) t.model = config::resolve_model(o.model);
    if (!o.agent.empty()) {
        t.set_agent(agent_by_name(o.agent));
        if (!o.trajectory.empty()) throw InputError("give --agent or --trajectory, not both");
    }
    if (o.step_per_row && o.trajectory.empty())
        throw InputError(
            "--step-per-row goes with --trajectory (in a trial YAML: trajectory: {file: FILE, "
            "step_per_row: true})");
    if (!o.trajectory.empty()) {
        TrajectoryParams params;
        params.step_per_row = o.step_per_row;
        t.set_agent(std::make_shared<TrajectorySpec>(TrajectorySpec::from_file(o.trajectory, params)));
    }
    if (o.seed) t.seed = *o.seed;
    if (!o.protocol.empty()) t.protocol.kind = parse_protocol(o.protocol);
    const auto hours = [](const char* flag, double h) {
        if (!(h > 0) || !std::isfinite(h)) throw InputError(std::string(flag) + " must be a positive number of hours");
        return h;
    };
    if (o.hours) t.protocol.explore_hours = t.protocol.sample_hours = hours("--hours", *o.hours);
    if (o.explore_hours) t.protocol.explore_hours = *o.explore_hours;
    if (o.sample_hours) t.protocol.sample_hours = *o.sample_hours;
    if (o.record_bvc) t.protocol.record_bvc = true;
    if (!o.extent.empty()) apply_extent(parse_extent(o.extent), t);
    o.run.check();
    t.check_runnable();  // fail early on bad worlds, start points and robots
    return t;
}

// Runs one trial into `out` through the trial pipeline, with progress on standard error.
void run_one(const TrialConfig& t, const std::filesystem::path& out, double checkpoint_minutes) {
    const ProgressStyle style = progress_style();
    const double total = t.protocol.seconds();
    if (const std::string note = t.agent->note(); !note.empty()) std::cerr << "bvc3d: note: " << note << "\n";
    InterruptGuard guard;
    RunControl control;
    control.stop = &stop_flag();
    control.checkpoint = out.string() + ".ckpt";
    control.checkpoint_minutes = checkpoint_minutes;
    const auto start = std::chrono::steady_clock::now();
    int printed_tenth = 0;
    control.progress = [&](double s, std::int64_t) {
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double left = s > 0 ? wall * (total - s) / s : 0.0;
        if (style == ProgressStyle::terminal) {
            std::fprintf(stderr, "\r  %.2f/%.2f simulated hours  ~%.0f s left   ", s / 3600, total / 3600, left);
        } else if (const int tenth = static_cast<int>(10 * s / total); tenth > printed_tenth && tenth < 10) {
            printed_tenth = tenth;  // a line per tenth of the trial: logs show where it is
            std::fprintf(stderr, "bvc3d: %.2f/%.2f simulated hours (%d%%), ~%.0f s left\n", s / 3600, total / 3600,
                         10 * tenth, left);
        }
    };
    GroupOutcome done;
    try {
        done = run_analyze_write({t}, {out}, control);
    } catch (const Interrupted&) {
        exit_interrupted();
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (style == ProgressStyle::terminal) std::fprintf(stderr, "\n");
    const auto& r = done.result;
    std::printf("wrote %s: %zu samples, %.0f steps/s\n", out.c_str(), r.t.size(),
                (r.stats.explore_steps + r.stats.sample_steps) / wall);
    if (const std::string note = t.agent->note(); !note.empty()) std::printf("  %s\n", note.c_str());
    if (t.place_cells_untrained())
        std::printf(
            "  no place-cell metrics: the place cells never learned (explore_hours 0, no weights given), "
            "their weights are the seed's random draw\n");
    else
        for (const auto& [name, v] : analysis::scalar_metrics(done.trials[0].metrics))
            std::printf("  %-16s %g\n", name.c_str(), v);
}

void add_run(CLI::App& app) {
    auto* cmd = app.add_subcommand("run", "Run one trial and write its HDF5 file");
    auto o = std::make_shared<TrialOptions>();
    o->run.checkpoint_minutes = 10;
    cmd->add_option("--config", o->config, "Trial YAML file (docs/experiments.md); flags below override it");
    auto* world = o->world.add_to(*cmd, "", "").front();
    world->description(world->get_description() + " [cross, or the --config file's]");
    auto* model = add_model_option(*cmd, o->model, ModelCount::one);
    model->description(model->get_description() + " [3d-0.2, or the --config file's]");
    cmd->add_option("--trajectory", o->trajectory,
                    "Follow this path instead of the random walk: a text file of t, x, y, [z], heading rows, "
                    "resampled to the model step (" +
                        format_number(TrajectoryParams{}.model_dt) + " s) unless they are at it");
    cmd->add_flag("--step-per-row", o->step_per_row,
                  "With --trajectory: one model step per row, whatever their interval (no resampling)");
    cmd->add_option("--agent", o->agent,
                    "The agent, by name: " + agent_names_text() + "; default " + agent_kinds().front().name);
    cmd->add_option("--seed", o->seed, "Random seed, 0 .. 2^64 - 1 (default 0)")->check(seed_check);
    cmd->add_option("--protocol", o->protocol, "explore_then_sample (the paper's, default) or online");
    cmd->add_option("--explore-hours", o->explore_hours, "Simulated hours of exploration (learning on)");
    cmd->add_option("--sample-hours", o->sample_hours, "Simulated hours of sampling (recorded)");
    cmd->add_option("--hours", o->hours, "Shorten both phases to this many simulated hours");
    cmd->add_flag("--record-bvc", o->record_bvc, "Also record the BVC rates");
    cmd->add_option("--extent", o->extent, extent_help);
    o->run.add_out(*cmd, "Trial file to write (default results/<trial name>.h5)", OutputKind::trial_file);
    o->run.add_checkpoint_minutes(*cmd);
    o->run.add_no_memory_check(*cmd);
    cmd->footer("Ctrl-C checkpoints and stops; running the same command again resumes and gives the same file.");
    cmd->callback([o] {
        const TrialConfig t = run_config(*o);
        const std::filesystem::path out = o->run.out.empty() ? std::filesystem::path("results") / (t.name() + ".h5")
                                                             : std::filesystem::path(o->run.out);
        check_output("--out", out, OutputKind::trial_file, o->run.outputs.force);  // the default's too
        const OutputLock lock = lock_output_file(out);
        if (trial_file_complete(out, t)) {
            std::cerr << "bvc3d: " << out.string() << " is complete with this configuration; nothing to do\n";
            return;
        }
        o->run.check_memory({t}, 1);
        run_one(t, out, o->run.checkpoint_minutes);
    });
}

struct PaperOptions {
    std::string models = "2d,3d-0.1,3d-0.2,3d-3l", tilts = "0,30,45,60", protocol, extent;
    std::string preset = "spec", choices;
    int seeds = 1;
    std::optional<double> hours;
    RunOptions run{"results/paper"};
};

// Models × tilts × seeds, seeds slowest.
std::vector<TrialConfig> paper_trials(const PaperOptions& o) {
    std::vector<ModelSpec> models;
    for (const auto& m : model_list(o.models, "--models")) models.push_back(config::resolve_model(m));
    std::vector<double> tilts;
    for (const auto& t : split_commas(o.tilts)) tilts.push_back(parse_number(t, "--tilts: a tilt"));
    if (tilts.empty()) throw InputError("--tilts lists no tilt");
    std::vector<std::string> choices = paper_preset(o.preset).choices;
    for (const auto& c : split_commas(o.choices)) choices.push_back(c);
    check_seed_count(o.seeds, {{models.size(), "models"}, {tilts.size(), "tilts"}});
    if (o.hours && (!(*o.hours > 0) || !std::isfinite(*o.hours)))
        throw InputError("--hours must be a positive number of hours");
    const ExtentOption extent = parse_extent(o.extent.empty() ? "data" : o.extent);
    std::vector<TrialConfig> trials;
    for (int seed = 0; seed < o.seeds; ++seed)
        for (double tilt : tilts)
            for (const auto& m : models) {
                TrialConfig t;
                t.world = WorldSpec{"cross", tilt, "+x+y"};
                t.model = m;
                t.protocol = protocol_preset("paper");
                t.seed = static_cast<std::uint64_t>(seed);
                apply_authors_choices(t, choices);
                if (!o.protocol.empty()) t.protocol.kind = parse_protocol(o.protocol);
                if (o.hours) t.protocol.explore_hours = t.protocol.sample_hours = *o.hours;
                apply_extent(extent, t);
                trials.push_back(t);
            }
    return trials;
}

void add_paper(CLI::App& app) {
    auto* cmd =
        app.add_subcommand("paper", "Run the paper's experiment: models x tilted worlds x seeds, summary, figures");
    auto o = std::make_shared<PaperOptions>();
    o->run.add_experiment_options(*cmd);
    cmd->add_option("--seeds", o->seeds, "Seeds per condition (0 .. N-1)")->capture_default_str();
    cmd->add_option("--hours", o->hours,
                    "Shorten both phases to H simulated hours (default: the paper's " +
                        protocol_hours_text(protocol_preset("paper")) + ")");
    add_model_option(*cmd, o->models, ModelCount::list, "--models");
    cmd->add_option("--tilts", o->tilts,
                    "Comma-separated tilts of the cross arena, degrees (its world is the paper's: the cross arena)")
        ->capture_default_str();
    cmd->add_option("--protocol", o->protocol, "explore_then_sample (default) or online");
    std::string presets, choice_names;
    for (const auto& p : paper_presets()) presets += "\n  " + p.name + ": " + p.description;
    for (const auto& c : authors_choices()) choice_names += "\n  " + c.name + ": " + c.description;
    cmd->add_option("--preset", o->preset, "The experiment's configuration:" + presets)->capture_default_str();
    cmd->add_option(
        "--authors-choices", o->choices,
        "Comma-separated authors' choices to switch on besides the preset's (docs/reproduction.md):" + choice_names);
    cmd->add_option("--extent", o->extent, extent_help);
    cmd->footer(
        "Writes one HDF5 file per trial, trials.csv, summary.csv, summary.md, and the figures and report.md (the\n"
        "Python module bvc3d.report, run with " BVC3D_PYTHON
        " or $BVC3D_PYTHON). Completed trials are skipped on\n"
        "a rerun; Ctrl-C stops cleanly and can be resumed.");
    cmd->callback([o] {
        o->run.check();
        run_experiment_in_folder(paper_trials(*o), o->run);
        std::printf("summary: %s/summary.md%s\n", o->run.out.c_str(),
                    o->run.no_figures ? "" : (", report: " + o->run.out + "/report.md").c_str());
    });
}

void add_analyze(CLI::App& app) {
    auto* cmd = app.add_subcommand("analyze", "Recompute the metrics of trial files, optionally with other parameters");
    struct Options {
        std::vector<std::string> files;
        TableOptions<analysis::AnalysisParams> analysis{analysis::AnalysisParams::table()};
        std::string extent, cells, out;
        Outputs outputs;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("files", o->files, "Trial files (.h5)")->required();
    o->outputs.add(*cmd, "--out", o->out, OutputKind::file,
                   "Write the recomputed metrics to this CSV: one row per file (file, trial, every metric, the "
                   "analysis parameters used)");
    o->analysis.add_to(*cmd);  // every key of the analysis table
    cmd->add_option("--extent", o->extent, extent_help);
    o->outputs.add(*cmd, "--cells", o->cells, OutputKind::file, "Write per-cell metrics of the first file to this CSV");
    const analysis::AnalysisParams flat = analysis::AnalysisParams::defaults(2),
                                   flying = analysis::AnalysisParams::defaults(3);
    std::string footer =
        "Each file is analyzed with the parameters its metrics were computed with; the options change only\n"
        "what they name (defaults:";
    std::size_t line = footer.size() - footer.rfind('\n');
    const auto& fields = analysis::AnalysisParams::table().fields();
    for (std::size_t i = 0; i < fields.size(); ++i) {  // the table's defaults, wrapped at 100 columns
        const auto& f = fields[i];
        std::string item = " " + option_name(f.key).substr(2) + " " + params::to_text(f.get(flat));
        if (f.get(flying) != f.get(flat))
            item += " (" + params::to_text(f.get(flying)) + " for flying agents' 3-D files)";
        item += i + 1 < fields.size() ? "," : ";";
        if (line + item.size() > 100) footer += "\n", item.erase(0, 1), line = 0;
        footer += item, line += item.size();
    }
    cmd->footer(footer + " docs/analysis.md, docs/flying.md).");
    cmd->callback([o] {
        const bool new_extent = !o->extent.empty();
        const ExtentOption extent = parse_extent(new_extent ? o->extent : "data");
        o->outputs.check();
        std::vector<TrialFileData> trials;
        std::vector<analysis::AnalysisParams> params;
        for (const auto& f : o->files) {  // all readable and their parameters valid before any output
            trials.push_back(read_trial_samples(f));
            analysis::AnalysisParams p = stored_analysis_params(trials.back(), f);
            o->analysis.apply(p);
            if (new_extent) {
                p.extent.reset();
                if (extent.kind == ExtentOption::Kind::bounds) p.extent = extent.bounds;
                if (extent.kind == ExtentOption::Kind::arena) p.extent = arena_extent(trials.back(), f);
            }
            p.validate();
            params.push_back(p);
        }
        int dims = 2;  // columns for the metrics of the files' largest dimension
        for (const auto& d : trials) dims = std::max(dims, d.dims);
        const auto columns = analysis::metric_names(dims);
        const auto& table = analysis::AnalysisParams::table();
        std::ostringstream text;
        CsvWriter csv(text);
        csv.field("file").field("trial");
        for (const auto& c : columns) csv.field(c);
        for (const auto& f : table.fields()) csv.field(f.key);
        csv.end_row();
        for (std::size_t i = 0; i < trials.size(); ++i) {
            const auto& d = trials[i];
            const Eigen::Map<const analysis::RowMatrixXf> rates(d.rates.data(), static_cast<Eigen::Index>(d.x.size()),
                                                                static_cast<Eigen::Index>(d.n_place));
            analysis::Points positions(static_cast<Eigen::Index>(d.x.size()), d.dims);
            for (std::size_t k = 0; k < d.x.size(); ++k) {
                positions(static_cast<Eigen::Index>(k), 0) = d.x[k];
                positions(static_cast<Eigen::Index>(k), 1) = d.y[k];
                if (d.dims == 3) positions(static_cast<Eigen::Index>(k), 2) = d.z[k];
            }
            // A block per trial, two metrics a line: it fits a terminal of 80 columns (--out has them all).
            std::printf("%s (%s)\n", printable(d.name).c_str(), printable(o->files[i]).c_str());
            // Untrained place cells (the seed's random weights, never learned): their metrics mean nothing.
            const bool untrained = d.place_weights == "untrained";
            if (untrained)
                std::printf("  no place-cell metrics: its place cells never learned (place_weights untrained)\n");
            const auto m = analysis::analyze_trial<float>(positions, rates, params[i]);
            const auto values = untrained ? std::vector<std::pair<std::string, double>>{} : analysis::scalar_metrics(m);
            csv.field(o->files[i]).field(d.name);
            for (std::size_t c = 0; c < columns.size(); ++c) {
                const auto it =
                    std::find_if(values.begin(), values.end(), [&](const auto& v) { return v.first == columns[c]; });
                const bool has = it != values.end();
                if (!untrained) {
                    if (has) std::printf("  %-22s %12.6g", columns[c].c_str(), it->second);
                    else std::printf("  %-22s %12s", columns[c].c_str(), "-");
                    std::printf("%s", c % 2 == 1 || c + 1 == columns.size() ? "\n" : "  ");
                }
                csv.field(has ? std::optional<double>(it->second) : std::nullopt);
            }
            for (const auto& f : table.fields()) csv.field(params::to_text(f.get(params[i])));
            csv.end_row();
            if (i == 0 && !o->cells.empty()) {
                AtomicFile f(o->cells);
                CsvWriter cells(f.stream());
                // field_area is m² of hexagons in 2-D, m³ of voxels in 3-D; isotropy only for 3-D files.
                const bool three = m.dims == 3;
                for (const char* name : {"cell", "modality", "peak_rate", "mean_rate", "field_area", "spatial_info"})
                    cells.field(name);
                if (three) cells.field("isotropy");
                cells.end_row();
                for (std::size_t c = 0; c < m.modality.size(); ++c) {
                    cells.field(c).field(m.modality[c]).field(m.cells.peak_rate[c]).field(m.cells.mean_rate[c]);
                    cells.field(m.cells.field_area[c]).field(m.cells.spatial_info[c]);
                    if (three) cells.field(m.isotropy[c]);
                    cells.end_row();
                }
                f.commit();
            }
        }
        if (!o->out.empty()) {
            write_file_atomically(o->out, text.str());
            std::printf("wrote %s\n", o->out.c_str());
        }
    });
}

void add_summarize(CLI::App& app) {
    auto* cmd = app.add_subcommand("summarize",
                                   "Write trials.csv, summary.csv/.md and the figures for a folder of trial files");
    struct Options {
        std::string dir;
        bool no_figures = false, skip_unreadable = false, allow_mixed = false;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("folder", o->dir, "Folder of trial files")->required();
    add_no_figures_option(*cmd, o->no_figures, "the figures and report.md");
    cmd->add_flag(
        "--skip-unreadable", o->skip_unreadable,
        "Leave out .h5 files that are not readable trial files (each named on standard error) instead of stopping");
    cmd->add_flag("--allow-mixed", o->allow_mixed,
                  "Put trials of different protocols, durations or analysis parameters into one table");
    cmd->callback([o] {
        std::error_code ec;
        if (!std::filesystem::is_directory(o->dir, ec))
            throw InputError("'" + o->dir + "' is not a folder" +
                             (std::filesystem::exists(o->dir, ec) ? "" : " (it does not exist)"));
        const OutputLock lock = lock_output_folder(o->dir);
        std::vector<std::filesystem::path> candidates, files;
        for (const auto& e : std::filesystem::directory_iterator(o->dir))
            if (e.path().extension() == ".h5") candidates.push_back(e.path());
        std::sort(candidates.begin(), candidates.end());
        for (const auto& f : candidates) {
            try {
                read_summary(f);
                files.push_back(f);
            } catch (const InputError& e) {
                if (!o->skip_unreadable)
                    throw InputError(std::string(e.what()) + " (remove it, or pass --skip-unreadable to leave it out)");
                std::fprintf(stderr, "bvc3d: warning: skipping %s\n", printable(e.what()).c_str());
            }
        }
        if (files.empty()) throw InputError("'" + o->dir + "' holds no readable trial files (*.h5)");
        summarize(o->dir, files, !o->no_figures, o->allow_mixed);
        std::printf("%zu trials summarized in %s/summary.md\n", files.size(), o->dir.c_str());
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

// bvc3d replay / localize / map / export-scans: real LiDAR recordings (docs/recordings.md).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>

#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/csv.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/experiment/pipeline.hpp"
#include "bvc3d/experiment/replay.hpp"
#include "bvc3d/recording/bag.hpp"
#include "bvc3d/recording/bag_writer.hpp"
#include "bvc3d/recording/extrinsics.hpp"
#include "bvc3d/recording/pcd.hpp"
#include "bvc3d/recording/ply.hpp"
#include "bvc3d/recording/recording.hpp"
#include "bvc3d/recording/voxel_map.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "option_groups.hpp"
#include "python_module.hpp"
#include "recording_options.hpp"
#include "run_options.hpp"

namespace bvc3d::cli {

namespace {

namespace fs = std::filesystem;

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// A progress line on a terminal ("\r  what i/n"), nothing otherwise.
class ProgressLine {
public:
    ProgressLine() : tty_(::isatty(STDERR_FILENO)) {}
    ~ProgressLine() { done(); }
    void show(const std::string& what, std::size_t i, std::size_t n) {
        if (!tty_) return;
        std::fprintf(stderr, "\r  %s %zu/%zu   ", what.c_str(), i, n);
        shown_ = true;
    }
    void done() {
        if (shown_) std::fprintf(stderr, "\n");
        shown_ = false;
    }

private:
    bool tty_;
    bool shown_ = false;
};

// Scans to replay: a recording (--scans, --poses), or a simulated sensor along a path in a world.
struct SourceOptions {
    std::string scans, poses, trajectory, sensor;
    WorldOptions world;
    bool step_per_row = false;
    RecordingOptions recording;
    PreprocessOptions preprocess;

    void add_to(CLI::App& cmd) {
        cmd.add_option("--scans", scans, "Scan folder, scan list file or one scan (PCD, PLY, KITTI .bin)");
        cmd.add_option("--poses", poses, "Pose file of the scans (KITTI, TUM or 4x4 rows)");
        recording.add_to(cmd);
        world.add_to(cmd, "Instead of a recording, to simulate a sensor in: ", "");
        cmd.add_option(
            "--trajectory", trajectory,
            "With --world: the sensor's path, rows t, x, y, [z], heading[, pitch, roll] (a header names them), "
            "resampled to the model step unless they are at it");
        cmd.add_flag("--step-per-row", step_per_row,
                     "With --trajectory: one model step (one scan) per row, whatever their interval");
        add_sensor_option(cmd, sensor, "With --world: ");
        preprocess.add_to(cmd);
    }
    ReplaySource get() const {
        const bool recorded = !scans.empty() || !poses.empty() || recording.has_bag();
        const bool simulated = world.given() || !trajectory.empty() || !sensor.empty() || step_per_row;
        if (recorded == simulated)
            throw InputError(
                "give either a recording (--scans and --poses, or --bag) or a simulation (--world, --trajectory, "
                "--sensor)");
        if (recorded) {
            if (scans.empty() && !recording.has_bag()) throw InputError("--poses needs --scans");
            return recorded_source(recording.open_any(scans, poses), preprocess.get());
        }
        if (world.world.empty() || trajectory.empty() || sensor.empty())
            throw InputError("a simulated replay needs --world, --trajectory and --sensor");
        const WorldSpec w = world.spec();
        warn_left_out(w.resolve());  // fail early on bad worlds
        TrajectoryParams params;
        params.step_per_row = step_per_row;
        auto path = std::make_shared<const TrajectorySpec>(TrajectorySpec::from_file(trajectory, params));
        if (const std::string note = path->note(); !note.empty()) std::cerr << "bvc3d: note: " << note << "\n";
        return simulated_source(w, path, config::resolve_sensor(sensor), preprocess.get());
    }
};

std::shared_ptr<const InitialWeights> weights_from(const std::string& file) {
    if (file.empty()) return nullptr;
    return weights_from_trial_file(file);
}

// ---------------------------------------------------------------------------------------------
// replay

void add_replay(CLI::App& app) {
    auto* cmd = app.add_subcommand(
        "replay", "Run a recording's scans through a model; write a trial file with every scan's rates");
    struct Options {
        SourceOptions source;
        std::string model, weights, out;
        bool learn = false;
        std::uint64_t seed = 0;
        Outputs outputs;
    };
    auto o = std::make_shared<Options>();
    o->source.add_to(*cmd);
    add_model_option(*cmd, o->model, ModelCount::one)->required();
    cmd->add_flag("--learn", o->learn, "Place cells learn while replaying (Oja's rule); default: frozen");
    cmd->add_option("--weights", o->weights, "Start from the trained weights of this trial file (same model)");
    cmd->add_option("--seed", o->seed, "Seed of the initial weights when no --weights is given")
        ->capture_default_str()
        ->check(seed_check);
    o->outputs.add(*cmd, "--out", o->out, OutputKind::trial_file,
                   "Trial file to write (default results/<recording>_<model>.h5)");
    cmd->footer(
        "Each scan is one model step at its pose: its points are rotated into the world frame (gravity-aligned),\n"
        "kept within the range limits, and each model reads the upper half (3-D presets) or the horizontal slice\n"
        "(2-D models). The trial file records every scan's x, y, z, heading and time (from 0; the recording's\n"
        "first time is the attribute recording_t0), its BVC rates and place-cell rates (docs/recordings.md).");
    cmd->callback([o] {
        const ReplaySource source = o->source.get();
        const TrialConfig t =
            replay_trial(source, config::resolve_model(o->model), o->learn, weights_from(o->weights), o->seed);
        const fs::path out =
            o->out.empty() ? fs::path("results") / (t.world_label() + "_" + t.model.name + ".h5") : fs::path(o->out);
        check_output("--out", out, OutputKind::trial_file, o->outputs.force);
        const OutputLock lock = lock_output_file(out);
        const std::size_t n = source.path->steps().size();
        ProgressLine line;
        RunControl control;
        control.progress_every = 1;
        control.progress = [&](double, std::int64_t steps) { line.show("scan", static_cast<std::size_t>(steps), n); };
        const auto start = std::chrono::steady_clock::now();
        const GroupOutcome done = run_analyze_write({t}, {out}, control);
        line.done();
        const double wall = seconds_since(start);
        std::printf("replayed %zu scans of %s through %s in %.2f s (%.1f scans/s): %s\n", done.result.t.size(),
                    t.world_label().c_str(), t.model.name.c_str(), wall, static_cast<double>(n) / wall, out.c_str());
        if (t.place_cells_untrained())
            std::printf(
                "  place cells frozen at the seed's random weights (no --weights, no --learn): their rates are "
                "recorded, their metrics are not (place_weights: untrained)\n");
    });
}

// ---------------------------------------------------------------------------------------------
// localize

// One side of a localization (templates or queries): a trial file, or a recording to replay.
struct Side {
    std::string file;  // a trial file (may hold {model})
    std::shared_ptr<const recording::Recording> recording;
    std::vector<std::size_t> keep;  // scans of the recording used (all when empty)
};

struct SideRates {
    analysis::RowMatrixXf rates;
    analysis::Points xyz;
    std::vector<std::size_t> index;  // scan or sample index of each row
};

std::string with_model(const std::string& pattern, const std::string& model) {
    std::string s = pattern;
    for (auto at = s.find("{model}"); at != std::string::npos; at = s.find("{model}", at + model.size()))
        s.replace(at, 7, model);
    return s;
}

SideRates rows_of(const analysis::RowMatrixXf& rates, const analysis::Points& xyz,
                  const std::vector<std::size_t>& keep) {
    SideRates r;
    if (keep.empty()) {
        r.rates = rates;
        r.xyz = xyz;
        for (Eigen::Index i = 0; i < rates.rows(); ++i) r.index.push_back(static_cast<std::size_t>(i));
        return r;
    }
    r.rates.resize(static_cast<Eigen::Index>(keep.size()), rates.cols());
    r.xyz.resize(static_cast<Eigen::Index>(keep.size()), 3);
    for (std::size_t k = 0; k < keep.size(); ++k) {
        r.rates.row(static_cast<Eigen::Index>(k)) = rates.row(static_cast<Eigen::Index>(keep[k]));
        r.xyz.row(static_cast<Eigen::Index>(k)) = xyz.row(static_cast<Eigen::Index>(keep[k]));
    }
    r.index = keep;
    return r;
}

SideRates side_from_file(const std::string& file, const ModelSpec& model, bool bvc) {
    const TrialRates t = read_trial_rates(file, bvc);
    const std::size_t expected =
        bvc ? static_cast<std::size_t>(model.bvc.n_cells()) : static_cast<std::size_t>(model.place.n_place);
    if (t.n_cells != expected)
        throw InputError("trial file '" + file + "' has " + std::to_string(t.n_cells) + " cells per sample; model '" +
                         model.name + "' has " + std::to_string(expected));
    const auto n = static_cast<Eigen::Index>(t.x.size());
    analysis::Points xyz(n, 3);
    for (Eigen::Index i = 0; i < n; ++i) {
        const auto k = static_cast<std::size_t>(i);
        xyz.row(i) << t.x[k], t.y[k], t.z[k];
    }
    return rows_of(Eigen::Map<const analysis::RowMatrixXf>(t.rates.data(), n, static_cast<Eigen::Index>(t.n_cells)),
                   xyz, {});
}

struct LocalizeRow {
    std::string model;
    SideRates templates, queries;
    analysis::LocalizationResult result;
};

std::string f3(double v) {
    char s[32];
    std::snprintf(s, sizeof s, "%.3f", v);
    return s;
}

void write_localization(const fs::path& dir, const std::vector<LocalizeRow>& rows, bool bvc) {
    const std::string rates = bvc ? "bvc" : "place";
    AtomicFile summary_file(dir / "localization.csv"), queries_file(dir / "queries.csv"),
        templates_file(dir / "templates.csv");
    CsvWriter summary(summary_file.stream()), queries(queries_file.stream()), templates(templates_file.stream());
    summary.row("model", "rates", "queries", "templates", "undecoded", "median_m", "mean_m", "within_1m", "within_2m",
                "vertical_median_m", "vertical_mean_m", "chance_median_m", "chance_mean_m", "chance_within_1m",
                "chance_within_2m", "nearest_median_m", "nearest_mean_m", "nearest_within_1m", "nearest_within_2m");
    queries.row("model", "query", "x", "y", "z", "decoded", "decoded_x", "decoded_y", "decoded_z", "similarity",
                "error_m", "vertical_error_m", "nearest_m");
    templates.row("model", "template", "x", "y", "z");
    std::string md =
        "| model | rates | queries | templates | median (m) | mean (m) | ≤ 1 m | ≤ 2 m | chance median | chance ≤ 2 m "
        "| "
        "nearest median | nearest ≤ 1 m |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const auto& row : rows) {
        const auto& r = row.result;
        const auto& s = r.decoded_summary;
        summary.row(row.model, rates, row.queries.rates.rows(), row.templates.rates.rows(), r.n_undecoded, s.median,
                    s.mean, s.within_1m, s.within_2m, r.vertical_median, r.vertical_mean, r.chance.median,
                    r.chance.mean, r.chance.within_1m, r.chance.within_2m, r.nearest.median, r.nearest.mean,
                    r.nearest.within_1m, r.nearest.within_2m);
        md += "| " + row.model + " | " + rates + " | " + std::to_string(row.queries.rates.rows()) + " | " +
              std::to_string(row.templates.rates.rows()) + " | " + f3(s.median) + " | " + f3(s.mean) + " | " +
              f3(s.within_1m) + " | " + f3(s.within_2m) + " | " + f3(r.chance.median) + " | " + f3(r.chance.within_2m) +
              " | " + f3(r.nearest.median) + " | " + f3(r.nearest.within_1m) + " |\n";
        for (std::size_t i = 0; i < r.decoded.size(); ++i) {
            const auto q = static_cast<Eigen::Index>(i);
            const long d = r.decoded[i];
            queries.field(row.model).field(row.queries.index[i]);
            queries.field(row.queries.xyz(q, 0)).field(row.queries.xyz(q, 1)).field(row.queries.xyz(q, 2));
            const std::optional<Eigen::Index> t = d >= 0 ? std::optional<Eigen::Index>(d) : std::nullopt;
            queries.field(t ? std::optional<std::size_t>(row.templates.index[static_cast<std::size_t>(d)])
                            : std::nullopt);
            for (int axis = 0; axis < 3; ++axis)
                queries.field(t ? std::optional<double>(row.templates.xyz(*t, axis)) : std::nullopt);
            queries.row(r.similarity[i], r.error[i], r.vertical_error[i], r.nearest_error[i]);
        }
        for (Eigen::Index j = 0; j < row.templates.xyz.rows(); ++j)
            templates.row(row.model, row.templates.index[static_cast<std::size_t>(j)], row.templates.xyz(j, 0),
                          row.templates.xyz(j, 1), row.templates.xyz(j, 2));
    }
    for (AtomicFile* f : {&summary_file, &queries_file, &templates_file}) f->commit();
    write_file_atomically(dir / "localization.md", md);
}

void add_localize(CLI::App& app) {
    auto* cmd = app.add_subcommand("localize", "Localize query scans against template scans (a table and a figure)");
    struct Options {
        std::string templates, template_poses, queries, query_poses, scans, poses, models, rates = "bvc", weights;
        std::string out = "results/localization";
        int split = 0;
        bool no_figures = false;
        RecordingOptions recording;
        PreprocessOptions preprocess;
        Outputs outputs;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--templates", o->templates,
                    "Templates: a trial file ({model} stands for each model's name), a scan folder/list or a bag");
    cmd->add_option("--template-poses", o->template_poses, "Pose file of the template scans");
    cmd->add_option("--queries", o->queries,
                    "Queries: a trial file (may contain {model}), a scan folder/list or a bag (same topics)");
    cmd->add_option("--query-poses", o->query_poses, "Pose file of the query scans");
    cmd->add_option("--scans", o->scans, "One recording for both, split by --split (instead of --templates/--queries)");
    cmd->add_option("--poses", o->poses, "Pose file of --scans");
    cmd->add_option("--split", o->split, "With --scans: scan i is a query when i mod N = 1, else a template")
        ->capture_default_str();
    add_model_option(*cmd, o->models, ModelCount::list)->required();
    cmd->add_option("--rates", o->rates, "Decode on 'bvc' rates (default) or 'place' rates")->capture_default_str();
    cmd->add_option("--weights", o->weights,
                    "With --rates place: trained weights for replayed recordings, a trial file (may contain {model})");
    o->recording.add_to(*cmd);
    o->preprocess.add_to(*cmd);
    o->outputs.add(*cmd, "--out", o->out, OutputKind::folder,
                   "Folder for localization.csv/.md, queries.csv, templates.csv, localization.png");
    add_no_figures_option(*cmd, o->no_figures, "the figure");
    cmd->footer(
        "Each query is decoded to the template whose population vector is most cosine-similar; the error is the\n"
        "horizontal distance between their positions (and, apart, the vertical one). Chance: a uniformly random\n"
        "template; nearest: the template nearest to each query (the best possible). Recordings are replayed in\n"
        "memory with each model (frozen place cells: --weights, or the seed-0 draw); trial files are read as they\n"
        "are (docs/recordings.md#localize).");
    cmd->callback([o] {
        if (o->rates != "bvc" && o->rates != "place") throw InputError("--rates must be 'bvc' or 'place'");
        const bool bvc = o->rates == "bvc";
        const auto models = model_list(o->models);
        const RecordedReturnParams pre = o->preprocess.get();
        o->outputs.check();

        Side templates, queries;
        if (!o->scans.empty() || o->recording.has_bag()) {
            if (!o->templates.empty() || !o->queries.empty())
                throw InputError("give either --scans (or --bag) with --split, or --templates and --queries");
            if (o->split < 2) throw InputError("--scans needs --split N (N >= 2): scan i is a query when i mod N = 1");
            const auto rec = o->recording.open_any(o->scans, o->poses);
            templates.recording = queries.recording = rec;
            for (std::size_t i = 0; i < rec->size(); ++i)
                (i % static_cast<std::size_t>(o->split) == 1 ? queries : templates).keep.push_back(i);
        } else {
            if (o->templates.empty() || o->queries.empty())
                throw InputError("give --templates and --queries (or --scans with --split)");
            auto side = [&](const std::string& what, const std::string& poses) {
                Side s;
                if (fs::path(what).extension() == ".h5") {
                    if (!poses.empty()) throw InputError("'" + what + "' is a trial file: it needs no pose file");
                    s.file = what;
                } else if (RecordingOptions::is_bag(what)) {
                    if (!poses.empty())
                        throw InputError("'" + what + "' is a bag: its poses come from --pose-topic or --tf-frames");
                    s.recording = o->recording.open_bag(what);
                } else {
                    s.recording = o->recording.open(what, poses);
                }
                return s;
            };
            templates = side(o->templates, o->template_poses);
            queries = side(o->queries, o->query_poses);
        }

        // Every model on each recording at once: one replay per recording, its scans read once.
        std::vector<ModelSpec> specs;
        for (const auto& m : models) specs.push_back(config::resolve_model(m));
        ProgressLine line;
        std::map<const recording::Recording*, GroupResult> replays;
        for (const Side* s : {&templates, &queries}) {
            if (!s->recording || replays.count(s->recording.get())) continue;
            const ReplaySource source = recorded_source(s->recording, pre);
            std::vector<TrialConfig> trials;
            for (std::size_t k = 0; k < specs.size(); ++k)
                trials.push_back(replay_trial(source, specs[k], false,
                                              bvc ? nullptr : weights_from(with_model(o->weights, specs[k].name))));
            if (!bvc && o->weights.empty())
                std::fprintf(
                    stderr,
                    "bvc3d: warning: place-cell rates without --weights come from untrained (seed 0) weights\n");
            RunControl control;
            control.progress_every = 1;
            const std::string what = s->recording->name + " scan";
            const std::size_t n = s->recording->size();
            control.progress = [&](double, std::int64_t steps) { line.show(what, static_cast<std::size_t>(steps), n); };
            replays[s->recording.get()] = run_replay(trials, control);
            line.done();
        }
        std::vector<LocalizeRow> rows;
        for (std::size_t k = 0; k < specs.size(); ++k) {
            auto rates_of = [&](const Side& s) {
                if (!s.file.empty()) return side_from_file(with_model(s.file, specs[k].name), specs[k], bvc);
                const ReplayRates r = replay_rates(replays.at(s.recording.get()), k, bvc);
                return rows_of(r.rates, r.xyz, s.keep);
            };
            LocalizeRow row;
            row.model = specs[k].name;
            row.templates = rates_of(templates);
            row.queries = rates_of(queries);
            row.result = analysis::localize(row.templates.rates, row.templates.xyz, row.queries.rates, row.queries.xyz);
            rows.push_back(std::move(row));
        }
        const OutputLock lock = lock_output_folder(o->out);  // made only now: an error above leaves nothing
        write_localization(o->out, rows, bvc);
        std::printf("%-12s %7s %9s %8s %8s %6s %6s | %14s %12s | %14s %13s\n", "model", "queries", "templates",
                    "median_m", "mean_m", "<=1m", "<=2m", "chance_median", "chance_<=2m", "nearest_median",
                    "nearest_<=1m");
        for (const auto& row : rows) {
            const auto& r = row.result;
            std::printf("%-12s %7ld %9ld %8.3f %8.3f %6.3f %6.3f | %14.3f %12.3f | %14.3f %13.3f\n", row.model.c_str(),
                        static_cast<long>(row.queries.rates.rows()), static_cast<long>(row.templates.rates.rows()),
                        r.decoded_summary.median, r.decoded_summary.mean, r.decoded_summary.within_1m,
                        r.decoded_summary.within_2m, r.chance.median, r.chance.within_2m, r.nearest.median,
                        r.nearest.within_1m);
            if (r.n_undecoded)
                std::printf("  %s: %zu queries undecoded (no positive similarity)\n", row.model.c_str(), r.n_undecoded);
        }
        if (!o->no_figures && run_python_module("bvc3d.localization_figure", {o->out}).status != 0)
            throw InputError("the figure failed; the tables are in '" + o->out + "'; rerun it with:\n  " +
                             python_command().shell_line("bvc3d.localization_figure", {o->out}));
        std::printf("tables: %s/localization.md, localization.csv, queries.csv%s\n", o->out.c_str(),
                    o->no_figures ? "" : ", figure: localization.png");
    });
}

// ---------------------------------------------------------------------------------------------
// map

void add_map(CLI::App& app) {
    auto* cmd = app.add_subcommand(
        "map", "Build a point map from a recording: its scans in the world frame, voxel-downsampled");
    struct Options {
        std::string scans, poses, out;
        recording::VoxelMapParams params;
        RecordingOptions recording;
        Outputs outputs;
    };
    auto o = std::make_shared<Options>();
    o->params.min_range = 0.3;
    cmd->add_option("--scans", o->scans, "Scan folder, scan list file or one scan");
    cmd->add_option("--poses", o->poses, "Pose file of the scans");
    o->recording.add_to(*cmd);
    cmd->add_option("--voxel", o->params.voxel, "m, voxel edge: one point (the mean) per occupied voxel")
        ->capture_default_str();
    cmd->add_option("--min-range", o->params.min_range, "m: nearer points are left out (the carrier)")
        ->capture_default_str();
    cmd->add_option("--max-range", o->params.max_range, "m: farther points are left out (0: no limit)")
        ->capture_default_str();
    cmd->add_option("--min-points", o->params.min_points, "Voxels with fewer points are left out")
        ->capture_default_str();
    o->outputs
        .add(*cmd, "--out", o->out, OutputKind::file, "Map to write: .ply (binary, float) or .pcd (binary, float)")
        ->required();
    cmd->footer(
        "The map is a point cloud in the recording's world frame; a world YAML draws it as spheres with a\n"
        "point_cloud object (docs/worlds.md#point-clouds), so that a simulated robot or sensor can use it.");
    cmd->callback([o] {
        const auto ext = fs::path(o->out).extension().string();
        if (ext != ".ply" && ext != ".pcd") throw InputError("--out must end in .ply or .pcd");
        o->outputs.check();
        if (o->scans.empty() && !o->recording.has_bag()) throw InputError("give --scans and --poses, or --bag");
        const auto rec = o->recording.open_any(o->scans, o->poses);
        recording::VoxelMap map(o->params);
        ProgressLine line;
        const auto start = std::chrono::steady_clock::now();
        for (std::size_t i = 0; i < rec->size(); ++i) {
            line.show(rec->name + " scan", i + 1, rec->size());
            try {
                map.add(rec->load(i), rec->poses[i].world_from_sensor);
            } catch (const InputError& e) {  // a point out of reach: name the recording and the scan
                const std::string text = e.what();
                if (text.rfind("recording '", 0) == 0) throw;
                throw InputError("recording '" + rec->name + "', scan " + std::to_string(i) + " (" +
                                 rec->store->scan_name(i) + ")" + rec->pose_origin(i) + ": " + text);
            }
        }
        line.done();
        const recording::PointCloud cloud = map.cloud();
        if (cloud.size() == 0) throw InputError("the map is empty: no point passed the range limits and --min-points");
        if (ext == ".ply") recording::write_ply(o->out, cloud);
        else recording::write_pcd(o->out, cloud);
        std::printf("%zu scans, %zu points -> %zu voxels of %g m in %.1f s: %s\n", rec->size(), map.points_added(),
                    cloud.size(), o->params.voxel, seconds_since(start), o->out.c_str());
    });
}

// ---------------------------------------------------------------------------------------------
// export-scans

// The bags export-scans writes, one row each: the format's name and the extension its file's name ends
// in (none: a ROS 2 bag folder). Every other format is a folder of scan files
// (recording::parse_scan_write_format).
struct BagExport {
    std::string name, extension, what;  // no extension: the bag is a folder
    recording::BagFormat format;
    bool is_folder() const { return extension.empty(); }
    std::string written() const { return is_folder() ? what : what + " (a " + extension + " file)"; }
};
const std::vector<BagExport>& bag_exports() {
    static const std::vector<BagExport> bags{
        {"ros1", ".bag", "a ROS 1 bag", recording::BagFormat::ros1},
        {"mcap", ".mcap", "a ROS 2 bag in one MCAP file", recording::BagFormat::mcap},
        {"ros2", "", "a ROS 2 bag folder (metadata.yaml and an .mcap)", recording::BagFormat::ros2}};
    return bags;
}

// The format and the output's name agree: a bag's file ends in its extension, a folder (of scans or a
// ROS 2 bag) does not end in a bag file's (InputError saying what to give instead). Then the rule for
// outputs that exist.
void check_export_out(const std::string& format, const std::string& out, bool force) {
    const std::string ext = fs::path(out).extension().string();
    for (const auto& b : bag_exports())
        if (b.name == format && !b.is_folder()) {
            if (ext != b.extension)
                throw InputError("--format " + format + " writes " + b.what + ", one file: --out must end in " +
                                 b.extension + ", got '" + out + "'");
            return check_output("--out", out, OutputKind::file, force);
        }
    const auto bag_folder = std::find_if(bag_exports().begin(), bag_exports().end(),
                                         [&](const BagExport& b) { return b.name == format && b.is_folder(); });
    const std::string writes = bag_folder != bag_exports().end() ? bag_folder->what : "a folder of scans";
    for (const auto& b : bag_exports())
        if (!b.is_folder() && ext == b.extension)
            throw InputError("--format " + format + " writes " + writes + ", but --out '" + out + "' is named as " +
                             b.what + ": give --format " + b.name + " for a " + b.extension +
                             " file, or a folder's name");
    check_output("--out", out, OutputKind::folder, force);
}

void add_export_scans(CLI::App& app) {
    auto* cmd = app.add_subcommand("export-scans", "Write simulated scans along a path as a recording (scans + poses)");
    struct Options {
        WorldOptions world;
        std::string trajectory, sensor = "spherical", format = "pcd-f8", out;
        std::optional<double> hours;
        std::uint64_t seed = 0;
        double start_time = recording::BagWriteOptions{}.start;
        Outputs outputs;
    };
    auto o = std::make_shared<Options>();
    o->world.add_to(*cmd);
    cmd->add_option("--trajectory", o->trajectory,
                    "Path: rows t, x, y, [z], heading[, pitch, roll] (a header names them)");
    cmd->add_option("--hours", o->hours, "Instead of --trajectory: this many hours of the seeded random walk");
    cmd->add_option("--seed", o->seed, "Seed of the random walk and of the sensor's noise")
        ->capture_default_str()
        ->check(seed_check);
    add_sensor_option(*cmd, o->sensor);
    std::string bags, bag_names;
    for (const auto& b : bag_exports()) {
        bags += "; " + b.name + ": " + b.written();
        bag_names += (bag_names.empty() ? "" : " or ") + b.name;
    }
    cmd->add_option("--format", o->format,
                    "pcd (float32), pcd-f8 (float64), ply, kitti (.bin): a folder of scans" + bags)
        ->capture_default_str();
    o->outputs
        .add(*cmd, "--out", o->out, OutputKind::file_or_folder,
             "Folder to write: 000000.<ext> ..., poses.txt, scans.txt; with " + bag_names +
                 ": the bag (a file whose name ends as the format's; ros2: the bag's folder)")
        ->required();
    cmd->add_option("--start-time", o->start_time,
                    "ros1, mcap, ros2: seconds added to every stamp (ROS takes a zero stamp for 'no time')")
        ->capture_default_str();
    cmd->footer(
        "Each scan holds the hits in the sensor's own frame (x forward, z up; tilted with the pose's pitch and\n"
        "roll); poses.txt holds each sensor's world-from-sensor pose (4x4 rows with the time). Replaying the\n"
        "folder gives the simulation's returns back (docs/recordings.md#export-scans). A bag holds /points\n"
        "(sensor_msgs/PointCloud2, float64 x y z in frame 'sensor'), /odom (nav_msgs/Odometry, map <- sensor)\n"
        "and /tf (the same transform): replay it with --bag OUT --cloud-topic /points --pose-topic /odom\n"
        "(docs/ros.md#export).");
    cmd->callback([o] {
        const auto bag = std::find_if(bag_exports().begin(), bag_exports().end(),
                                      [&](const BagExport& b) { return b.name == o->format; });
        const bool is_bag = bag != bag_exports().end();
        recording::ScanWriteFormat format = recording::ScanWriteFormat::pcd_f8;
        if (!is_bag) try {
                format = recording::parse_scan_write_format(o->format);
            } catch (const InputError& e) {
                std::string names;
                for (const auto& b : bag_exports()) names += ", " + b.name;
                throw InputError("--format: " + std::string(e.what()) + names);
            }
        if (is_bag && !(o->start_time >= 0)) throw InputError("--start-time must be >= 0");
        if (o->trajectory.empty() == !o->hours.has_value()) throw InputError("give --trajectory or --hours, not both");
        if (o->hours && !(*o->hours > 0)) throw InputError("--hours must be positive");
        check_export_out(o->format, o->out, o->outputs.force);
        const World world(o->world.resolve());
        const Lidar lidar(config::resolve_sensor(o->sensor));
        std::vector<ModelStep> steps;
        if (o->hours) {
            steps = random_walk(world, *o->hours, o->seed);
        } else {
            TrajectoryParams per_row;  // a scan at each row, as a scanner along the path takes them
            per_row.step_per_row = true;
            const TrajectorySpec path = TrajectorySpec::from_file(o->trajectory, per_row);
            path.check_world(world.description());  // a row outside the world, named as `run` names it
            steps = path.steps();
        }
        const std::uint64_t noise_seed = hash_u64(o->seed, static_cast<std::uint64_t>(Stream::sensor_noise), 0);
        std::vector<recording::PointCloud> clouds;
        std::vector<recording::PoseRecord> poses;
        ProgressLine line;
        Scan scan;
        for (std::size_t i = 0; i < steps.size(); ++i) {
            line.show("scan", i + 1, steps.size());
            const Pose& p = steps[i].pose;
            lidar.scan(world, p, scan, NoiseKey{noise_seed, i});
            recording::PoseRecord pose;
            pose.world_from_sensor = sensor_pose(p, lidar.spec().height);
            pose.time = steps[i].t;
            recording::PointCloud cloud = points_from_returns(scan, pose.world_from_sensor.linear());
            if (cloud.size() == 0)
                throw InputError("step " + std::to_string(i) + " at (" + num(p.x) + ", " + num(p.y) +
                                 "): the sensor sees nothing, and a recording's scan cannot be empty");
            clouds.push_back(std::move(cloud));
            poses.push_back(pose);
        }
        line.done();
        if (is_bag) {
            recording::BagWriteOptions b;
            b.format = bag->format;
            b.start = o->start_time;
            recording::write_bag(o->out, clouds, poses, b);
        } else {
            recording::write_recording(o->out, clouds, poses, format);
        }
        std::printf("wrote %zu scans and their poses to %s\n", clouds.size(), o->out.c_str());
    });
}

// ---------------------------------------------------------------------------------------------
// bag-info

// /tf messages bag-info reads for the links (a tf tree's links all appear within its first seconds).
constexpr std::size_t tf_messages_read = 100;

void add_bag_info(CLI::App& app) {
    auto* cmd = app.add_subcommand("bag-info", "List a ROS bag's topics: types, encodings, counts and time spans");
    auto path = std::make_shared<std::string>();
    cmd->add_option("bag", *path, "A ROS 1 .bag, an .mcap file or a ROS 2 bag folder (metadata.yaml)")->required();
    cmd->footer(
        "Times are the messages' log (receive) times in seconds. For a PointCloud2 topic, the frame and size of\n"
        "its first cloud; for /tf and /tf_static, the links parent -> child (of their first 100 messages).\n"
        "Then read the bag as a recording with --bag, --cloud-topic and --pose-topic (or --tf-frames\n"
        "FIXED,SENSOR) (docs/ros.md). A bag path may be a ROS 2 bag folder, its metadata.yaml, or a storage\n"
        "file alone (.db3, .mcap).");
    cmd->callback([path] {
        const auto bag = recording::open_bag(*path);
        std::size_t total = 0;
        double first = 0, last = 0;
        for (const auto& t : bag->topics()) {
            if (t.count == 0) continue;
            first = total == 0 ? t.first : std::min(first, t.first);
            last = total == 0 ? t.last : std::max(last, t.last);
            total += t.count;
        }
        std::printf("%s: %s, %zu topics, %zu messages, %.3f to %.3f s (%.3f s)\n", path->c_str(), bag->format().c_str(),
                    bag->topics().size(), total, first, last, last - first);
        std::printf("%-28s %-32s %-8s %9s %18s %18s %10s\n", "topic", "type", "encoding", "messages", "first_s",
                    "last_s", "span_s");
        for (std::size_t i = 0; i < bag->topics().size(); ++i) {
            const auto& t = bag->topics()[i];
            std::printf("%-28s %-32s %-8s %9zu %18.6f %18.6f %10.3f\n", t.name.c_str(), t.type.c_str(),
                        t.encoding_name.c_str(), t.count, t.first, t.last, t.last - t.first);
            if (t.count == 0) continue;
            if (t.encoding == recording::MessageEncoding::unknown) {  // listed; its messages are not read
                std::printf("    (not read: bvc3d reads cdr and ros1)\n");
                continue;
            }
            const auto kind = recording::message_kind(t.type);
            if (kind == recording::MessageKind::point_cloud2) {
                const auto c = bag->cloud(i, 0);
                std::string fields;
                for (const auto& f : c.fields) fields += (fields.empty() ? "" : ",") + f.name;
                std::printf("    frame '%s', %u x %u points, fields %s%s\n", c.frame_id.c_str(), c.height, c.width,
                            fields.c_str(), c.is_bigendian ? ", big-endian" : "");
            } else if (kind == recording::MessageKind::tf) {
                // The links of its first messages: not every chunk of a large bag is read for them.
                std::map<std::string, std::string> links;
                for (std::size_t k = 0; k < std::min<std::size_t>(t.count, tf_messages_read); ++k)
                    for (const auto& x : bag->transforms(i, k)) links[x.child] = x.parent;
                for (const auto& [child, parent] : links) std::printf("    %s -> %s\n", parent.c_str(), child.c_str());
            } else if (kind == recording::MessageKind::odometry || kind == recording::MessageKind::pose_stamped) {
                const auto p = bag->pose(i, 0);
                std::printf("    frame '%s'%s%s\n", p.parent.c_str(), p.child.empty() ? "" : " <- ", p.child.c_str());
            }
        }
    });
}

}  // namespace

void add_recording_commands(CLI::App& app) {
    add_replay(app);
    add_localize(app);
    add_map(app);
    add_export_scans(app);
    add_bag_info(app);
}

}  // namespace bvc3d::cli

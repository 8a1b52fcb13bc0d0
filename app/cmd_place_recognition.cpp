// bvc3d place-recognition: the field's protocol on a recording or a simulated route
// (docs/place-recognition.md).
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/csv.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/place_recognition.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "option_groups.hpp"
#include "python_module.hpp"
#include "recording_options.hpp"
#include "table_options.hpp"

namespace bvc3d::cli {

namespace {

namespace fs = std::filesystem;

void write_tables(const fs::path& dir, const PlaceRecognitionOutcome& r) {
    AtomicFile queries_file(dir / "queries.csv"), summary_file(dir / "summary.csv"), details_file(dir / "details.csv"),
        pr_file(dir / "pr.csv"), scans_file(dir / "scans.csv");
    CsvWriter queries(queries_file.stream()), summary(summary_file.stream()), details(details_file.stream()),
        pr(pr_file.stream()), scans(scans_file.stream());
    queries.row("descriptor", "query", "match", "distance", "match_m", "has_revisit", "correct");
    summary.row("descriptor", "protocol", "recall_at_1", "f1_max", "auc", "queries", "revisits", "timed");
    pr.row("descriptor", "protocol", "threshold", "precision", "recall");
    details.row("descriptor", "protocol", "uses_heading", "recall_at_1", "f1_max", "auc", "queries", "revisits",
                "correct", "median_match_m", "describe_s", "search_s", "timed");
    for (const auto& d : r.descriptors) {
        const auto& rows = d.result.rows;
        for (std::size_t i = 0; i < rows.query.size(); ++i)
            queries.row(d.spec.label, rows.query[i], rows.match[i], rows.distance[i], rows.match_m[i],
                        bool(rows.has_revisit[i]), bool(rows.correct[i]));
        const auto& s = d.result.summary;
        summary.row(d.spec.label, r.protocol, s.recall_at_1, s.f1_max, s.auc, s.queries, s.revisits, r.timed);
        details.row(d.spec.label, r.protocol, d.spec.uses_heading(), s.recall_at_1, s.f1_max, s.auc, s.queries,
                    s.revisits, s.correct, s.median_match_m, d.describe_seconds, d.search_seconds, r.timed);
        const auto& c = d.result.curve;
        for (std::size_t k = 0; k < c.threshold.size(); ++k)
            pr.row(d.spec.label, r.protocol, c.threshold[k], c.precision[k], c.recall[k]);
    }
    scans.row("scan", "t", "x", "y", "z", "heading", "drift");
    for (Eigen::Index i = 0; i < r.positions.rows(); ++i) {
        const auto k = static_cast<std::size_t>(i);
        scans.row(i, r.times[k], r.positions(i, 0), r.positions(i, 1), r.positions(i, 2), r.heading[k], r.drift[k]);
    }
    for (AtomicFile* f : {&queries_file, &summary_file, &details_file, &pr_file, &scans_file}) f->commit();
}

// The figure module's arguments: the folder, and a simulated route's world as `route --figure` passes it
// (--world and whichever of --tilt, --lean, --missing-models were given), drawn under the route.
std::vector<std::string> figure_arguments(const std::string& out, const WorldOptions& world) {
    std::vector<std::string> args{out};
    if (world.world.empty()) return args;  // a recording: no world to draw
    args.insert(args.end(), {"--world", world.world});
    if (world.tilt) args.insert(args.end(), {"--tilt", num(*world.tilt)});
    if (world.lean) args.insert(args.end(), {"--lean", *world.lean});
    if (world.missing_models) args.insert(args.end(), {"--missing-models", *world.missing_models});
    return args;
}

std::string descriptor_help() {
    std::string text = "Descriptors (--descriptors, comma-separated):\n";
    for (const auto& k : descriptor_kinds()) {
        const std::string name = k.name + (k.takes_model ? ":MODEL" : "");
        text += "  " + name + std::string(name.size() < 18 ? 18 - name.size() : 1, ' ') + k.description + "\n";
    }
    return text;
}

}  // namespace

void add_place_recognition_command(CLI::App& app) {
    auto* cmd = app.add_subcommand(
        "place-recognition",
        "Recognise revisited places from scans alone: BVC rates, place cells and Scan Context, the field's protocol");
    struct Options {
        std::string scans, poses, route, sensor, descriptors, database, queries;
        std::string out = "results/place-recognition";
        WorldOptions world;
        RecordingOptions recording;
        PreprocessOptions preprocess;
        TableOptions<analysis::LoopClosureParams> loop{analysis::LoopClosureParams::table()};
        PlaceRecognitionOptions run;
        bool no_figures = false;
        Outputs outputs;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--scans", o->scans, "Scan folder, scan list file (PCD, PLY, KITTI .bin) of a recording");
    cmd->add_option("--poses", o->poses, "Pose file of the scans (KITTI, TUM or 4x4 rows): the ground truth");
    o->recording.add_to(*cmd);
    o->world.add_to(*cmd, "Instead of a recording, to drive a sensor through: ", "");
    cmd->add_option("--route", o->route,
                    "With --world: the route, a trajectory file (rows t, x, y, [z], heading[, pitch, roll])");
    add_sensor_option(*cmd, o->sensor, "With --world: ");
    cmd->add_option("--descriptors", o->descriptors, "Comma-separated descriptors (below)")->required();
    cmd->add_option("--database", o->database, "Split protocol: the database scans A:B (both included)");
    cmd->add_option("--queries", o->queries, "Split protocol: the query scans C:D (both included)");
    static const analysis::LoopClosureParams loop_defaults;
    o->loop.add_to(*cmd, {}, &loop_defaults);
    cmd->add_option("--drift-deg-per-sqrt-min", o->run.drift_deg_per_sqrt_min,
                    "bvc-drift: the heading's random-walk drift, degrees after one minute (SD)")
        ->capture_default_str();
    cmd->add_option("--seed", o->run.seed, "Seed of the drift, the place cells' initial weights and sensor noise")
        ->capture_default_str()
        ->check(seed_check);
    add_jobs_option(*cmd, o->run.threads, "Scans described");
    o->preprocess.add_to(*cmd);
    o->outputs.add(*cmd, "--out", o->out, OutputKind::folder,
                   "Folder for queries.csv, summary.csv, details.csv, pr.csv, scans.csv, place-recognition.png");
    add_no_figures_option(*cmd, o->no_figures, "the figure");
    cmd->footer(
        descriptor_help() +
        "Sequential protocol (default): each scan queries the scans older than the exclusion window; it has a\n"
        "revisit when one of them lies within --revisit-m. Split (--database, --queries): each query scan\n"
        "queries the database. A query's match is right when it lies within --revisit-m; precision and recall\n"
        "over thresholds on the distance give the curve, its area (AUC) and F1max; recall@1 is the fraction\n"
        "of revisits whose match is right. --min-range, --max-range and --slice-half-width-deg say how the BVC\n"
        "models read a scan (as replay reads it); Scan Context reads every point within 80 m\n"
        "(docs/place-recognition.md).");
    cmd->callback([o] {
        check_jobs(o->run.threads);
        o->loop.apply(o->run.loop);
        const auto descriptors = parse_descriptors(o->descriptors);
        if (!o->database.empty()) o->run.database = analysis::parse_scan_span(o->database, "--database");
        if (!o->queries.empty()) o->run.queries = analysis::parse_scan_span(o->queries, "--queries");
        o->run.preprocess = o->preprocess.get();
        const bool recorded = !o->scans.empty() || !o->poses.empty() || o->recording.has_bag();
        const bool simulated = o->world.given() || !o->route.empty() || !o->sensor.empty();
        if (recorded == simulated)
            throw InputError(
                "give either a recording (--scans and --poses, or --bag) or a route (--world, --route, --sensor)");
        std::unique_ptr<ScanSequence> seq;
        if (recorded) {
            if (o->scans.empty() && !o->recording.has_bag()) throw InputError("--poses needs --scans");
            seq = std::make_unique<RecordingSequence>(o->recording.open_any(o->scans, o->poses));
        } else {
            if (o->world.world.empty() || o->route.empty() || o->sensor.empty())
                throw InputError("a simulated route needs --world, --route and --sensor");
            auto world = std::make_shared<const World>(o->world.resolve());
            seq = std::make_unique<SimulatedSequence>(world, read_trajectory_file(o->route), o->route,
                                                      config::resolve_sensor(o->sensor), o->run.seed);
        }
        query_plan(*seq, o->run);  // bad spans and windows fail before anything is written
        o->outputs.check();
        ensure_writable_directory(o->out);
        const bool tty = ::isatty(STDERR_FILENO);
        o->run.progress = [tty](std::size_t done, std::size_t n) {
            if (tty && (done % 16 == 0 || done == n)) std::fprintf(stderr, "\r  scan %zu/%zu   ", done, n);
            if (tty && done == n) std::fprintf(stderr, "\n");
        };
        const auto start = std::chrono::steady_clock::now();
        const PlaceRecognitionOutcome r = run_place_recognition(*seq, descriptors, o->run);
        const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        write_tables(o->out, r);
        // Wall times are parts of the total; the threads' own times (reading, describe_s) add up over the threads.
        std::printf(
            "%s: %zu scans, %s protocol, %.1f s in all (%.1f s describing the scans on %zu threads, which "
            "spent %.1f s of their time reading them)\n",
            r.sequence.c_str(), static_cast<std::size_t>(r.positions.rows()), r.protocol.c_str(), wall,
            r.describe_wall_seconds, r.threads, r.read_seconds);
        if (!r.timed && r.protocol == "sequential")
            std::printf(
                "the scans have no times (neither their list nor their poses give them): the exclusion window is "
                "--exclude-scans %d alone, not --exclude-seconds, and the drift counts one scan a second\n",
                o->run.loop.exclude_scans);
        std::printf("%-28s %7s %8s %11s %7s %7s %10s %11s %9s\n", "descriptor", "queries", "revisits", "recall@1",
                    "F1max", "AUC", "heading", "describe_s", "search_s");
        for (const auto& d : r.descriptors) {
            const auto& s = d.result.summary;
            std::printf("%-28s %7zu %8zu %11.3f %7.3f %7.3f %10s %11.2f %9.2f\n", d.spec.label.c_str(), s.queries,
                        s.revisits, s.recall_at_1, s.f1_max, s.auc, d.spec.uses_heading() ? "uses" : "no",
                        d.describe_seconds, d.search_seconds);
        }
        std::printf("(describe_s: the threads' time, summed; search_s: wall time)\n");
        if (!r.descriptors.empty() && r.descriptors.front().result.summary.revisits == 0)
            std::printf(
                "no query has a revisit (an older scan outside the exclusion window within --revisit-m %s m): "
                "recall, F1max and AUC are undefined (nan) and the curve is empty\n",
                num(o->run.loop.revisit_m).c_str());
        // A simulated route is drawn over its world's floor plan; a recording has no world to draw.
        const std::vector<std::string> figure_args = figure_arguments(o->out, o->world);
        if (!o->no_figures && run_python_module("bvc3d.place_recognition_figure", figure_args).status != 0)
            throw InputError("the figure failed; the tables are in '" + o->out + "'; rerun it with:\n  " +
                             python_command().shell_line("bvc3d.place_recognition_figure", figure_args));
        std::printf("tables: %s/summary.csv, queries.csv, details.csv, pr.csv, scans.csv%s\n", o->out.c_str(),
                    o->no_figures ? "" : ", figure: place-recognition.png");
    });
}

}  // namespace bvc3d::cli

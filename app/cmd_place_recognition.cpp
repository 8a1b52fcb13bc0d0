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
#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/place_recognition.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "python_module.hpp"
#include "recording_options.hpp"
#include "run_options.hpp"

namespace bvc3d::cli {

namespace {

namespace fs = std::filesystem;

std::string flag(bool b) { return b ? "1" : "0"; }

void write_tables(const fs::path& dir, const PlaceRecognitionOutcome& r) {
    std::string queries = "descriptor,query,match,distance,match_m,has_revisit,correct\n";
    std::string summary = "descriptor,protocol,recall_at_1,f1_max,auc,queries,revisits,timed\n";
    std::string pr = "descriptor,protocol,threshold,precision,recall\n";
    std::string details =
        "descriptor,protocol,uses_heading,recall_at_1,f1_max,auc,queries,revisits,correct,median_match_m,"
        "describe_s,search_s,timed\n";
    for (const auto& d : r.descriptors) {
        const auto& rows = d.result.rows;
        for (std::size_t i = 0; i < rows.query.size(); ++i)
            queries += d.spec.label + "," + std::to_string(rows.query[i]) + "," + std::to_string(rows.match[i]) + "," +
                       num(rows.distance[i]) + "," + num(rows.match_m[i]) + "," + flag(rows.has_revisit[i]) + "," +
                       flag(rows.correct[i]) + "\n";
        const auto& s = d.result.summary;
        summary += d.spec.label + "," + r.protocol + "," + num(s.recall_at_1) + "," + num(s.f1_max) + "," + num(s.auc) +
                   "," + std::to_string(s.queries) + "," + std::to_string(s.revisits) + "," + flag(r.timed) + "\n";
        details += d.spec.label + "," + r.protocol + "," + flag(d.spec.uses_heading()) + "," + num(s.recall_at_1) +
                   "," + num(s.f1_max) + "," + num(s.auc) + "," + std::to_string(s.queries) + "," +
                   std::to_string(s.revisits) + "," + std::to_string(s.correct) + "," + num(s.median_match_m) + "," +
                   num(d.describe_seconds) + "," + num(d.search_seconds) + "," + flag(r.timed) + "\n";
        const auto& c = d.result.curve;
        for (std::size_t k = 0; k < c.threshold.size(); ++k)
            pr += d.spec.label + "," + r.protocol + "," + num(c.threshold[k]) + "," + num(c.precision[k]) + "," +
                  num(c.recall[k]) + "\n";
    }
    std::string scans = "scan,t,x,y,z,heading,drift\n";
    for (Eigen::Index i = 0; i < r.positions.rows(); ++i) {
        const auto k = static_cast<std::size_t>(i);
        scans += std::to_string(i) + "," + num(r.times[k]) + "," + num(r.positions(i, 0)) + "," +
                 num(r.positions(i, 1)) + "," + num(r.positions(i, 2)) + "," + num(r.heading[k]) + "," +
                 num(r.drift[k]) + "\n";
    }
    write_file_atomically(dir / "queries.csv", queries);
    write_file_atomically(dir / "summary.csv", summary);
    write_file_atomically(dir / "details.csv", details);
    write_file_atomically(dir / "pr.csv", pr);
    write_file_atomically(dir / "scans.csv", scans);
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
        std::string scans, poses, world, route, sensor, descriptors, database, queries;
        std::string out = "results/place-recognition";
        RecordingOptions recording;
        PreprocessOptions preprocess;
        PlaceRecognitionOptions run;
        bool no_figure = false;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--scans", o->scans, "Scan folder, scan list file (PCD, PLY, KITTI .bin) of a recording");
    cmd->add_option("--poses", o->poses, "Pose file of the scans (KITTI, TUM or 4x4 rows): the ground truth");
    o->recording.add_to(*cmd);
    cmd->add_option("--world", o->world, "Instead of a recording: a world (preset or YAML) to drive a sensor through");
    cmd->add_option("--route", o->route,
                    "With --world: the route, a trajectory file (rows t, x, y, [z], heading[, pitch, roll])");
    cmd->add_option("--sensor", o->sensor, "With --world: the sensor (horizontal, spherical or a sensor YAML)");
    cmd->add_option("--descriptors", o->descriptors, "Comma-separated descriptors (below)")->required();
    cmd->add_option("--database", o->database, "Split protocol: the database scans A:B (both included)");
    cmd->add_option("--queries", o->queries, "Split protocol: the query scans C:D (both included)");
    cmd->add_option("--exclude-scans", o->run.loop.exclude_scans,
                    "Sequential protocol: scan i matches only scans j with i - j > this")
        ->capture_default_str();
    cmd->add_option("--exclude-seconds", o->run.loop.exclude_seconds,
                    "Sequential protocol: and, when the scans carry times, t_i - t_j > this (s)")
        ->capture_default_str();
    cmd->add_option("--revisit-m", o->run.loop.revisit_m, "A match this close (horizontally, m) is right")
        ->capture_default_str();
    cmd->add_option("--drift-deg-per-sqrt-min", o->run.drift_deg_per_sqrt_min,
                    "bvc-drift: the heading's random-walk drift, degrees after one minute (SD)")
        ->capture_default_str();
    cmd->add_option("--seed", o->run.seed, "Seed of the drift, the place cells' initial weights and sensor noise")
        ->capture_default_str()
        ->check(seed_check);
    cmd->add_option("--threads", o->run.threads, "Threads (0: every core)")->capture_default_str();
    o->preprocess.add_to(*cmd);
    cmd->add_option("--out", o->out,
                    "Folder for queries.csv, summary.csv, details.csv, pr.csv, scans.csv, place-recognition.png")
        ->capture_default_str();
    cmd->add_flag("--no-figure", o->no_figure, "Skip the figure");
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
        RunOptions jobs;  // --jobs checked as every command that runs trials checks it
        jobs.jobs = o->run.threads;
        jobs.check();
        const auto descriptors = parse_descriptors(o->descriptors);
        if (!o->database.empty()) o->run.database = analysis::parse_scan_span(o->database, "--database");
        if (!o->queries.empty()) o->run.queries = analysis::parse_scan_span(o->queries, "--queries");
        o->run.preprocess = o->preprocess.get();
        const bool recorded = !o->scans.empty() || !o->poses.empty() || o->recording.has_bag();
        const bool simulated = !o->world.empty() || !o->route.empty() || !o->sensor.empty();
        if (recorded == simulated)
            throw InputError(
                "give either a recording (--scans and --poses, or --bag) or a route (--world, --route, --sensor)");
        std::unique_ptr<ScanSequence> seq;
        if (recorded) {
            if (o->scans.empty() && !o->recording.has_bag()) throw InputError("--poses needs --scans");
            seq = std::make_unique<RecordingSequence>(o->recording.open_any(o->scans, o->poses));
        } else {
            if (o->world.empty() || o->route.empty() || o->sensor.empty())
                throw InputError("a simulated route needs --world, --route and --sensor");
            auto world = std::make_shared<const World>(config::resolve_world(o->world));
            seq = std::make_unique<SimulatedSequence>(world, read_trajectory_file(o->route), o->route,
                                                      config::resolve_sensor(o->sensor), o->run.seed);
        }
        query_plan(*seq, o->run);  // bad spans and windows fail before anything is written
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
        if (!o->no_figure && run_python_module("bvc3d.place_recognition_figure", {o->out}).status != 0)
            throw InputError("the figure failed; the tables are in '" + o->out + "'; rerun it with:\n  " +
                             python_command().shell_line("bvc3d.place_recognition_figure", {o->out}));
        std::printf("tables: %s/summary.csv, queries.csv, details.csv, pr.csv, scans.csv%s\n", o->out.c_str(),
                    o->no_figure ? "" : ", figure: place-recognition.png");
    });
}

}  // namespace bvc3d::cli

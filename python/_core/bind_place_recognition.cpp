// Place recognition (docs/place-recognition.md): the protocol on a recording or a simulated route,
// the protocol's parts on arrays (bvc3d.analysis), and Scan Context.
#include "bindings.hpp"

#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/experiment/place_recognition.hpp"
#include "bvc3d/recording/recording.hpp"

namespace bvc3d::py {

namespace {

using ArrayF = pyb::array_t<float, pyb::array::c_style | pyb::array::forcecast>;

template <class T>
pyb::array_t<T> vec(const std::vector<T>& v) {
    return to_numpy(v.data(), {static_cast<pyb::ssize_t>(v.size())});
}
pyb::array_t<bool> flags(const std::vector<char>& v) {
    pyb::array_t<bool> a(static_cast<pyb::ssize_t>(v.size()));
    for (std::size_t i = 0; i < v.size(); ++i) a.mutable_data()[i] = v[i] != 0;
    return a;
}

pyb::dict curve_dict(const analysis::PrCurve& c) {
    pyb::dict d;
    d["threshold"] = vec(c.threshold);
    d["precision"] = vec(c.precision);
    d["recall"] = vec(c.recall);
    return d;
}

void add_summary(pyb::dict& d, const analysis::PrSummary& s) {
    d["recall_at_1"] = s.recall_at_1;
    d["f1_max"] = s.f1_max;
    d["auc"] = s.auc;
    d["queries"] = s.queries;
    d["revisits"] = s.revisits;
    d["n_correct"] = s.correct;
    d["median_match_m"] = s.median_match_m;
}

pyb::dict rows_dict(const analysis::QueryRows& r) {
    pyb::dict d;
    std::vector<std::int64_t> q(r.query.begin(), r.query.end()), m(r.match.begin(), r.match.end());
    d["query"] = vec(q);
    d["match"] = vec(m);
    d["distance"] = vec(r.distance);
    d["match_m"] = vec(r.match_m);
    d["has_revisit"] = flags(r.has_revisit);
    d["correct"] = flags(r.correct);
    return d;
}

// The tables of bvc3d place-recognition's CSV files, as dicts of columns.
pyb::dict outcome_dict(const PlaceRecognitionOutcome& r) {
    pyb::list q_desc, s_desc, s_protocol, p_desc, p_protocol, heading;
    std::vector<std::int64_t> q_query, q_match;
    std::vector<double> q_distance, q_match_m, s_recall, s_f1, s_auc, s_median, s_describe, s_search, p_threshold,
        p_precision, p_recall;
    std::vector<char> q_revisit, q_correct;
    std::vector<std::int64_t> s_queries, s_revisits;
    for (const auto& d : r.descriptors) {
        const auto& rows = d.result.rows;
        for (std::size_t i = 0; i < rows.query.size(); ++i) {
            q_desc.append(d.spec.label);
            q_query.push_back(static_cast<std::int64_t>(rows.query[i]));
            q_match.push_back(rows.match[i]);
            q_distance.push_back(rows.distance[i]);
            q_match_m.push_back(rows.match_m[i]);
            q_revisit.push_back(rows.has_revisit[i]);
            q_correct.push_back(rows.correct[i]);
        }
        const auto& s = d.result.summary;
        s_desc.append(d.spec.label);
        s_protocol.append(r.protocol);
        heading.append(d.spec.uses_heading());
        s_recall.push_back(s.recall_at_1);
        s_f1.push_back(s.f1_max);
        s_auc.push_back(s.auc);
        s_queries.push_back(static_cast<std::int64_t>(s.queries));
        s_revisits.push_back(static_cast<std::int64_t>(s.revisits));
        s_median.push_back(s.median_match_m);
        s_describe.push_back(d.describe_seconds);
        s_search.push_back(d.search_seconds);
        const auto& c = d.result.curve;
        for (std::size_t k = 0; k < c.threshold.size(); ++k) {
            p_desc.append(d.spec.label);
            p_protocol.append(r.protocol);
            p_threshold.push_back(c.threshold[k]);
            p_precision.push_back(c.precision[k]);
            p_recall.push_back(c.recall[k]);
        }
    }
    pyb::dict queries, summary, pr, scans, out;
    queries["descriptor"] = q_desc;
    queries["query"] = vec(q_query);
    queries["match"] = vec(q_match);
    queries["distance"] = vec(q_distance);
    queries["match_m"] = vec(q_match_m);
    queries["has_revisit"] = flags(q_revisit);
    queries["correct"] = flags(q_correct);
    summary["descriptor"] = s_desc;
    summary["protocol"] = s_protocol;
    summary["recall_at_1"] = vec(s_recall);
    summary["f1_max"] = vec(s_f1);
    summary["auc"] = vec(s_auc);
    summary["queries"] = vec(s_queries);
    summary["revisits"] = vec(s_revisits);
    summary["uses_heading"] = heading;
    summary["median_match_m"] = vec(s_median);
    summary["describe_s"] = vec(s_describe);
    summary["search_s"] = vec(s_search);
    summary["timed"] = pyb::list(pyb::cast(std::vector<bool>(r.descriptors.size(), r.timed)));
    pr["descriptor"] = p_desc;
    pr["protocol"] = p_protocol;
    pr["threshold"] = vec(p_threshold);
    pr["precision"] = vec(p_precision);
    pr["recall"] = vec(p_recall);
    const auto n = static_cast<pyb::ssize_t>(r.positions.rows());
    const analysis::Points& p = r.positions;
    std::vector<double> x(p.col(0).begin(), p.col(0).end()), y(p.col(1).begin(), p.col(1).end()),
        z(p.col(2).begin(), p.col(2).end());
    std::vector<std::int64_t> index(static_cast<std::size_t>(n));
    for (std::size_t i = 0; i < index.size(); ++i) index[i] = static_cast<std::int64_t>(i);
    scans["scan"] = vec(index);
    scans["t"] = vec(r.times);
    scans["x"] = vec(x);
    scans["y"] = vec(y);
    scans["z"] = vec(z);
    scans["heading"] = vec(r.heading);
    scans["drift"] = vec(r.drift);
    out["queries"] = queries;
    out["summary"] = summary;
    out["pr"] = pr;
    out["scans"] = scans;
    out["sequence"] = r.sequence;
    out["protocol"] = r.protocol;
    return out;
}

std::optional<analysis::ScanSpan> span_of(const pyb::object& obj, const char* name) {
    if (obj.is_none()) return std::nullopt;
    if (pyb::isinstance<pyb::str>(obj)) return analysis::parse_scan_span(obj.cast<std::string>(), name);
    const auto t = obj.cast<std::vector<std::int64_t>>();
    if (t.size() != 2 || t[0] < 0 || t[1] < 0)
        throw InputError(std::string(name) + " must be (first, last): two scan numbers >= 0, both included");
    if (t[0] > t[1]) throw InputError(std::string(name) + " is empty: its first scan comes after its last");
    return analysis::ScanSpan{static_cast<std::size_t>(t[0]), static_cast<std::size_t>(t[1])};
}

std::vector<double> reals_of(const pyb::object& obj, const char* name) {
    if (obj.is_none()) return {};
    const ArrayD a = real_array(obj, name);
    if (a.ndim() != 1) throw InputError(std::string(name) + " must be a 1-D array");
    return std::vector<double>(a.data(), a.data() + a.size());
}

ScanContextParams scan_context_params(const pyb::kwargs& kwargs) {
    ScanContextParams p;
    apply_kwargs(p, ScanContextParams::table(), kwargs);
    return p;
}

ScanContext context_of(const ArrayD& bins) {
    if (bins.ndim() != 2) throw InputError("Scan Context bins must be a 2-D array (rings, sectors)");
    return scan_context_from_bins(static_cast<int>(bins.shape(0)), static_cast<int>(bins.shape(1)),
                                  std::vector<double>(bins.data(), bins.data() + bins.size()));
}

}  // namespace

void bind_place_recognition(pyb::module_& m) {
    const std::vector<std::string> own = {"scans",         "poses",   "world",
                                          "route",         "sensor",  "descriptors",
                                          "database",      "queries", "drift_deg_per_sqrt_min",
                                          "seed",          "threads", "pose_format",
                                          "time_tolerance"};
    m.def(
        "place_recognition",
        [own](const pyb::object& scans, const pyb::object& poses, const pyb::object& world, const pyb::object& route,
              const pyb::object& sensor, const pyb::object& descriptors, const pyb::object& database,
              const pyb::object& queries, double drift, const pyb::object& seed, int threads,
              const std::string& pose_format, double time_tolerance, const pyb::kwargs& kwargs) {
            PlaceRecognitionOptions o;
            // Keywords: the protocol's table, then the preprocessing's.
            pyb::kwargs loop, pre;
            for (const auto& [k, v] : kwargs) {
                const std::string key = pyb::str(k);
                if (analysis::LoopClosureParams::table().find(key)) loop[k] = v;
                else pre[k] = v;
            }
            apply_kwargs(o.loop, analysis::LoopClosureParams::table(), loop);
            apply_kwargs(o.preprocess, RecordedReturnParams::table(), pre);
            o.database = span_of(database, "database");
            o.queries = span_of(queries, "queries");
            o.drift_deg_per_sqrt_min = drift;
            o.seed = seed_of(seed, "seed");
            o.threads = threads;
            const std::string list = pyb::isinstance<pyb::str>(descriptors) ? descriptors.cast<std::string>() : [&] {
                std::string s;
                for (const auto& d : descriptors.cast<std::vector<std::string>>()) s += (s.empty() ? "" : ",") + d;
                return s;
            }();
            const auto specs = parse_descriptors(list);
            std::unique_ptr<ScanSequence> seq;
            const bool recorded = !scans.is_none() || !poses.is_none();
            if (recorded == (!world.is_none() || !route.is_none() || !sensor.is_none()))
                throw InputError("give either a recording (scans, poses) or a route (world, route, sensor)");
            if (recorded && pyb::isinstance<recording::Recording>(scans)) {
                // A Recording however it was opened (Recording.open, or any other reader of one).
                if (!poses.is_none()) throw InputError("a Recording carries its poses: give no poses with it");
                seq = std::make_unique<RecordingSequence>(scans.cast<std::shared_ptr<recording::Recording>>());
            } else if (recorded) {
                if (scans.is_none() || poses.is_none()) throw InputError("a recording needs scans and poses");
                recording::RecordingOptions ro;
                ro.pose_format = recording::parse_pose_format(pose_format);
                ro.time_tolerance = time_tolerance;
                seq = std::make_unique<RecordingSequence>(
                    std::make_shared<const recording::Recording>(recording::open_recording(
                        pyb::str(scans).cast<std::string>(), pyb::str(poses).cast<std::string>(), ro)));
            } else {
                if (world.is_none() || route.is_none() || sensor.is_none())
                    throw InputError("a simulated route needs world, route and sensor");
                // The route's rows are the scans: a file's, or a dict's (one scan per row, as given).
                pyb::kwargs per_row;
                per_row["step_per_row"] = true;
                if (!pyb::isinstance<pyb::str>(route) && !pyb::hasattr(route, "__fspath__") &&
                    !pyb::isinstance<pyb::dict>(route))
                    throw InputError(
                        "route must be a trajectory file's path or a dict of arrays t, x, y, heading "
                        "(and optionally z, pitch, roll), not " +
                        type_name(route));
                const auto rows = trajectory_of(route, per_row);
                if (!pyb::isinstance<pyb::str>(sensor) && !pyb::isinstance<LidarSpec>(sensor))
                    throw InputError("sensor must be a sensor's name, a sensor YAML's path or a Sensor, not " +
                                     type_name(sensor));
                const LidarSpec s = pyb::isinstance<pyb::str>(sensor)
                                        ? config::resolve_sensor(sensor.cast<std::string>())
                                        : sensor.cast<LidarSpec>();
                seq = std::make_unique<SimulatedSequence>(world_of(world, "place_recognition: world"), rows->rows(),
                                                          rows->source(), s, o.seed);
            }
            const PlaceRecognitionOutcome r =
                interruptible([&](const std::atomic<bool>&) { return run_place_recognition(*seq, specs, o); });
            return outcome_dict(r);
        },
        pyb::arg("scans") = pyb::none(), pyb::arg("poses") = pyb::none(), pyb::kw_only(),
        pyb::arg("world") = pyb::none(), pyb::arg("route") = pyb::none(), pyb::arg("sensor") = pyb::none(),
        pyb::arg("descriptors") = "scan-context", pyb::arg("database") = pyb::none(), pyb::arg("queries") = pyb::none(),
        pyb::arg("drift_deg_per_sqrt_min") = 1.0, pyb::arg("seed") = 0, pyb::arg("threads") = 0,
        pyb::arg("pose_format") = "auto", pyb::arg("time_tolerance") = 0.05,
        (std::string(
             R"doc(Place recognition, the field's protocol (docs/place-recognition.md), as `bvc3d place-recognition`:
on a recording (scans, poses; or a Recording as scans) or a simulated route (world: a World, a preset or a world
file; route: a trajectory file or a dict of arrays t, x, y, heading[, z], one scan per row; sensor).
descriptors: a comma-separated string or a list of bvc:MODEL, bvc-drift:MODEL, bvc-free:MODEL,
place-cells:MODEL, scan-context. database, queries: (first, last) or "A:B" scans (both included) for
the split protocol; else sequential loop closure. Returns a dict of tables, each a dict of columns:
queries (descriptor, query, match, distance, match_m, has_revisit, correct), summary (descriptor,
protocol, recall_at_1, f1_max, auc, queries, revisits, uses_heading, median_match_m, describe_s,
search_s, timed: whether every scan had a time), pr (descriptor, protocol, threshold, precision, recall), scans
(scan, t, x, y, z, heading, drift); and sequence, protocol. Keywords: )doc") +
         describe(analysis::LoopClosureParams::table(), analysis::LoopClosureParams{}) +
         describe(RecordedReturnParams::table(), RecordedReturnParams{}))
            .c_str());

    m.def(
        "scan_context",
        [](const pyb::object& points, const pyb::kwargs& kwargs) {
            const ArrayD p = real_array(points, "points");
            if (p.ndim() != 2 || p.shape(1) != 3) throw InputError("points must be an (N, 3) array");
            const ScanContext sc = scan_context(std::span<const double>(p.data(), static_cast<std::size_t>(p.size())),
                                                scan_context_params(kwargs));
            pyb::dict d;
            d["bins"] = to_numpy(sc.bins.data(), {sc.rings, sc.sectors});
            d["ring_key"] = vec(sc.ring_key);
            return d;
        },
        pyb::arg("points"),
        (std::string(R"doc(Scan Context of (N, 3) points in a level frame that turns with the sensor (x forward, z up):
bins (rings, sectors), each the largest z + lidar_height of its points (0 when empty), and
ring_key (each ring's mean). Keywords: )doc") +
         describe(ScanContextParams::table(), ScanContextParams{}))
            .c_str());
    m.def(
        "scan_context_distance",
        [](const ArrayD& a, const ArrayD& b) {
            const auto r = scan_context_distance(context_of(a), context_of(b));
            return pyb::make_tuple(r.distance, r.shift);
        },
        pyb::arg("a"), pyb::arg("b"),
        R"doc(The Scan Context distance between two bins arrays (rings, sectors) and its shift: the mean over
sectors non-empty in both of 1 - cos of the columns a[:, (c + shift) % S] and b[:, c], minimised over
every shift (ties: the smallest); 1 for a shift with no such sector. Returns (distance, shift).)doc");

    auto a = m.attr("analysis").cast<pyb::module_>();
    a.def(
        "precision_recall",
        [](const pyb::object& distance, const pyb::object& correct, const pyb::object& has_revisit) {
            const auto d = reals_of(distance, "distance");
            const auto c = pyb::cast<std::vector<bool>>(
                pyb::module_::import("numpy").attr("asarray")(correct, "bool").attr("ravel")().attr("tolist")());
            const auto h = pyb::cast<std::vector<bool>>(
                pyb::module_::import("numpy").attr("asarray")(has_revisit, "bool").attr("ravel")().attr("tolist")());
            if (c.size() != d.size() || h.size() != d.size())
                throw InputError("distance, correct and has_revisit must have one value per query");
            analysis::QueryRows rows;
            for (std::size_t i = 0; i < d.size(); ++i) {
                if (c[i] && !h[i]) throw InputError("query " + std::to_string(i) + " is correct without a revisit");
                rows.query.push_back(i);
                rows.match.push_back(0);
                rows.distance.push_back(d[i]);
                rows.match_m.push_back(0.0);
                rows.correct.push_back(c[i]);
                rows.has_revisit.push_back(h[i]);
            }
            const auto curve = analysis::precision_recall(
                rows.distance, rows.correct, static_cast<std::size_t>(std::count(h.begin(), h.end(), true)));
            pyb::dict out = curve_dict(curve);
            add_summary(out, analysis::summarize(rows, curve));
            return out;
        },
        pyb::arg("distance"), pyb::arg("correct"), pyb::arg("has_revisit"),
        R"doc(The protocol's precision-recall curve and metrics from each query's distance, whether its match is
right and whether it has a revisit: threshold, precision, recall (as scikit-learn's
precision_recall_curve lists them, recall over the revisits), recall_at_1, f1_max, auc, queries,
revisits, n_correct (right matches).)doc");
    a.def(
        "loop_closure",
        [](const ArrayF& rates, const ArrayD& positions, const pyb::object& times, const pyb::object& database,
           const pyb::object& queries, int turns, int turn_size, const pyb::kwargs& kwargs) {
            if (rates.ndim() != 2) throw InputError("rates must be a 2-D array (scans, cells)");
            if (positions.ndim() != 2 || positions.shape(1) < 2)
                throw InputError("positions must be an (N, 2) or (N, 3) array");
            analysis::LoopClosureParams p;
            apply_kwargs(p, analysis::LoopClosureParams::table(), kwargs);
            const auto t = reals_of(times, "times");
            const auto db = span_of(database, "database"), qs = span_of(queries, "queries");
            if (db.has_value() != qs.has_value()) throw InputError("a split needs both database and queries");
            const auto n = static_cast<std::size_t>(rates.shape(0));
            const auto plan = db ? analysis::split_plan(n, *db, *qs) : analysis::sequential_plan(n, t, p);
            const Eigen::Map<const analysis::RowMatrixXf> r(rates.data(), rates.shape(0), rates.shape(1));
            const Eigen::Map<const analysis::Points> xy(positions.data(), positions.shape(0), positions.shape(1));
            const analysis::RateMatchIndex index(r, {turns, static_cast<std::size_t>(turn_size)});
            const auto result = analysis::evaluate(index, plan, xy, p.revisit_m);
            pyb::dict out = rows_dict(result.rows);
            out["curve"] = curve_dict(result.curve);
            add_summary(out, result.summary);
            out["protocol"] = plan.protocol;
            return out;
        },
        pyb::arg("rates"), pyb::arg("positions"), pyb::arg("times") = pyb::none(), pyb::arg("database") = pyb::none(),
        pyb::arg("queries") = pyb::none(), pyb::arg("turns") = 1, pyb::arg("turn_size") = 1,
        (std::string(
             R"doc(The protocol on given population vectors (one row per scan, float32) and positions (x, y[, z]):
sequential loop closure (times: one per scan, or None) or a split (database, queries: (first, last)).
Best match by cosine (distance 1 - cos; ties: the older scan); turns > 1: each query also turned by
turn_size values per step along its directions (a heading-free BVC match). Returns per query
(query, match, distance, match_m, has_revisit, correct), curve, recall_at_1, f1_max, auc, queries,
revisits, n_correct, median_match_m, protocol. Keywords: )doc") +
         describe(analysis::LoopClosureParams::table(), analysis::LoopClosureParams{}))
            .c_str());
}

}  // namespace bvc3d::py

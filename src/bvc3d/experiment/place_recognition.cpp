#include "bvc3d/experiment/place_recognition.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <numeric>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/parallel.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/place/place_cell_network.hpp"

namespace bvc3d {

const std::vector<DescriptorKind>& descriptor_kinds() {
    static const std::vector<DescriptorKind> kinds = {
        {"bvc", true, false, HeadingUse::pose,
         "BVC rates of MODEL (a preset or model YAML), allocentric: they read the pose's heading; cosine"},
        {"bvc-drift", true, false, HeadingUse::drifted,
         "the same with the heading drifting as odometry's does (--drift-deg-per-sqrt-min, seeded)"},
        {"bvc-free", true, false, HeadingUse::free,
         "BVC rates in the sensor's level frame (no heading), matched over the n_dir turns of the directions"},
        {"place-cells", true, true, HeadingUse::pose,
         "place-cell rates of MODEL's network learning online along the sequence (Oja), from bvc:MODEL"},
        {"scan-context", false, false, HeadingUse::none,
         "Scan Context (Kim & Kim 2018): 20 rings x 60 sectors to 80 m, ring-key k-d tree, column shifts"},
    };
    return kinds;
}

DescriptorSpec parse_descriptor(const std::string& text) {
    const auto colon = text.find(':');
    const std::string kind = text.substr(0, colon);
    DescriptorSpec d;
    d.label = text;
    for (const auto& k : descriptor_kinds())
        if (k.name == kind) d.kind = &k;
    if (!d.kind) {
        std::string list;
        for (const auto& k : descriptor_kinds())
            list += (list.empty() ? "" : ", ") + k.name + (k.takes_model ? ":MODEL" : "");
        throw InputError("unknown descriptor '" + text + "' (descriptors: " + list + ")");
    }
    if (d.kind->takes_model) {
        if (colon == std::string::npos || colon + 1 == text.size())
            throw InputError("descriptor '" + text + "' needs a model: " + kind + ":MODEL (a preset or a model YAML)");
        d.model = config::resolve_model(text.substr(colon + 1));
        d.label = kind + ":" + d.model->name;  // "bvc:street-2d" for bvc:docs/street-2d.yaml
    } else if (colon != std::string::npos) {
        throw InputError("descriptor '" + text + "': " + kind + " takes no model");
    }
    return d;
}

std::vector<DescriptorSpec> parse_descriptors(const std::string& list) {
    std::vector<DescriptorSpec> out;
    std::size_t start = 0;
    while (start <= list.size()) {
        const auto comma = std::min(list.find(',', start), list.size());
        const std::string item = list.substr(start, comma - start);
        if (!item.empty()) {
            DescriptorSpec d = parse_descriptor(item);
            for (const auto& e : out)
                if (e.label == d.label)
                    throw InputError("descriptor '" + item + "': '" + d.label +
                                     "' is listed twice (models are named by their `name`)");
            out.push_back(std::move(d));
        }
        start = comma + 1;
    }
    if (out.empty()) throw InputError("no descriptor given (--descriptors)");
    return out;
}

void PlaceRecognitionOptions::validate() const {
    loop.validate();
    preprocess.validate();
    scan_context.validate();
    if (!(drift_deg_per_sqrt_min >= 0) || !std::isfinite(drift_deg_per_sqrt_min))
        throw InputError("the heading drift (--drift-deg-per-sqrt-min) must be a finite number >= 0, got " +
                         format_number(drift_deg_per_sqrt_min));
    if (threads < 0) throw InputError("threads must be >= 0 (0: every core)");
}

std::vector<double> heading_drift(const std::vector<double>& times, double sigma_per_sqrt_min, std::uint64_t seed) {
    if (!(sigma_per_sqrt_min >= 0) || !std::isfinite(sigma_per_sqrt_min))
        throw InputError("the heading drift must be a finite number >= 0");
    std::vector<double> d(times.size(), 0.0);
    Rng rng(seed, Stream::heading_drift);
    for (std::size_t i = 1; i < times.size(); ++i) {
        const double dt = times[i] - times[i - 1];
        if (!(dt > 0)) throw InputError("heading drift: scan " + std::to_string(i) + "'s time does not follow");
        d[i] = d[i - 1] + rng.normal(0.0, sigma_per_sqrt_min * std::sqrt(dt / 60.0));
    }
    return d;
}

std::vector<float> turn_bvc_rates(std::span<const float> rates, int n_dir, int n_per_axis, int steps) {
    const auto dirs = static_cast<std::size_t>(n_dir), per = static_cast<std::size_t>(n_per_axis);
    if (n_dir < 1 || n_per_axis < 1 || rates.size() % (dirs * per) != 0)
        throw InputError("BVC rates of " + std::to_string(rates.size()) + " cells are not layers of " +
                         std::to_string(n_dir) + " x " + std::to_string(n_per_axis));
    const std::size_t s = static_cast<std::size_t>(((steps % n_dir) + n_dir) % n_dir);
    std::vector<float> out(rates.size());
    for (std::size_t l = 0; l < rates.size() / (dirs * per); ++l)
        for (std::size_t k = 0; k < dirs; ++k)
            for (std::size_t m = 0; m < per; ++m)
                out[(l * dirs + (k + s) % dirs) * per + m] = rates[(l * dirs + k) * per + m];
    return out;
}

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

Eigen::Matrix3d rotation_z(double angle) { return Eigen::AngleAxisd(angle, Vec3::UnitZ()).toRotationMatrix(); }

// The heading of a world-from-sensor rotation: the yaw of its forward axis on the floor.
double heading_of(const Eigen::Matrix3d& r) { return std::atan2(r(1, 0), r(0, 0)); }

// BVC rates of one model in one frame, for every scan (shared by the descriptors that read them).
struct RateStream {
    ModelSpec model;
    HeadingUse frame = HeadingUse::pose;
    ReturnSelection selection = ReturnSelection::all;
    bool keep_double = false;  // feeds a place-cell network, which reads the rates in double
    analysis::RowMatrixXf rates;
    std::vector<double> rates_double;
    std::vector<double> seconds;  // per thread
};

// What the scans are described by: the rate streams the descriptors read, and Scan Context.
struct Descriptions {
    std::vector<RateStream> streams;
    std::vector<std::optional<std::size_t>> stream_of;  // per descriptor; none: Scan Context
    bool scan_context = false;
    std::vector<ScanContext> contexts;
    std::vector<double> context_seconds, read_seconds;  // per thread
};

Descriptions descriptions_for(const std::vector<DescriptorSpec>& descriptors) {
    Descriptions d;
    for (const auto& spec : descriptors) {
        if (!spec.kind->takes_model) {
            d.scan_context = true;
            d.stream_of.emplace_back();
            continue;
        }
        const std::string key = config::model_to_yaml(*spec.model);
        auto same = [&](const RateStream& s) {
            return s.frame == spec.kind->heading && config::model_to_yaml(s.model) == key;
        };
        auto it = std::find_if(d.streams.begin(), d.streams.end(), same);
        if (it == d.streams.end()) {
            RateStream s;
            s.model = *spec.model;
            s.frame = spec.kind->heading;
            s.selection = selection_for(s.model.sensor, s.model.bvc.elevations.empty());
            it = d.streams.insert(d.streams.end(), std::move(s));
        }
        it->keep_double = it->keep_double || spec.kind->learns;
        d.stream_of.push_back(static_cast<std::size_t>(it - d.streams.begin()));
    }
    return d;
}

}  // namespace

std::vector<double> scan_times(const ScanSequence& seq) {
    std::vector<double> times(seq.size());
    for (std::size_t i = 0; i < seq.size(); ++i) {
        const auto t = seq.time(i);
        if (!t) {  // one scan per second, as replays count them
            for (std::size_t k = 0; k < seq.size(); ++k) times[k] = static_cast<double>(k);
            return times;
        }
        times[i] = *t;
    }
    return times;
}

analysis::QueryPlan query_plan(const ScanSequence& seq, const PlaceRecognitionOptions& o) {
    o.validate();
    if (o.database.has_value() != o.queries.has_value())
        throw InputError("a database/query split needs both --database and --queries");
    if (o.database) return analysis::split_plan(seq.size(), *o.database, *o.queries);
    bool timed = true;
    for (std::size_t i = 0; i < seq.size() && timed; ++i) timed = seq.time(i).has_value();
    const std::vector<double> times = timed ? scan_times(seq) : std::vector<double>{};
    return analysis::sequential_plan(seq.size(), times, o.loop);
}

namespace {

// Every scan read once, described by every stream and by Scan Context, on `threads` threads. `heading`
// and `drift` are each scan's (rad).
void describe_scans(const ScanSequence& seq, const std::vector<double>& heading, const std::vector<double>& drift,
                    const PlaceRecognitionOptions& o, std::size_t threads, Descriptions& d) {
    const std::size_t n = seq.size();
    for (auto& s : d.streams) {
        s.rates.resize(static_cast<Eigen::Index>(n), s.model.bvc.n_cells());
        if (s.keep_double) s.rates_double.resize(n * static_cast<std::size_t>(s.model.bvc.n_cells()));
        s.seconds.assign(threads, 0.0);
    }
    d.contexts.resize(d.scan_context ? n : 0);
    d.read_seconds.assign(threads, 0.0);
    d.context_seconds.assign(threads, 0.0);
    std::atomic<std::size_t> next{0}, done{0};
    std::mutex progress_lock;
    run_workers(threads, [&](std::size_t t) {
        std::vector<BoundaryVectorLayer> layers;
        for (const auto& s : d.streams) layers.emplace_back(s.model.bvc);
        Scan returns;
        std::vector<double> rates, level_xyz;
        for (std::size_t i; (i = next++) < n;) {
            poll_cancel();
            auto start = Clock::now();
            const recording::PointCloud cloud = seq.points(i);
            d.read_seconds[t] += since(start);
            const Eigen::Matrix3d r = seq.pose(i).linear();
            const Eigen::Matrix3d level = rotation_z(-heading[i]) * r;  // turns with the sensor, z up
            for (std::size_t k = 0; k < d.streams.size(); ++k) {
                RateStream& s = d.streams[k];
                start = Clock::now();
                const Eigen::Matrix3d rot = s.frame == HeadingUse::free      ? level
                                            : s.frame == HeadingUse::drifted ? rotation_z(drift[i]) * r
                                                                             : r;
                returns_from_points(cloud.xyz, rot, o.preprocess, s.selection, returns);
                rates.resize(layers[k].n_cells());
                layers[k].rates(returns, rates);
                for (std::size_t c = 0; c < rates.size(); ++c)
                    s.rates(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(c)) = static_cast<float>(rates[c]);
                if (s.keep_double) std::copy(rates.begin(), rates.end(), s.rates_double.begin() + i * rates.size());
                s.seconds[t] += since(start);
            }
            if (d.scan_context) {
                start = Clock::now();
                level_xyz.resize(cloud.xyz.size());
                for (std::size_t p = 0; p < cloud.size(); ++p) {
                    const Vec3 v = level * Vec3(cloud.xyz[3 * p], cloud.xyz[3 * p + 1], cloud.xyz[3 * p + 2]);
                    level_xyz[3 * p] = v.x(), level_xyz[3 * p + 1] = v.y(), level_xyz[3 * p + 2] = v.z();
                }
                d.contexts[i] = scan_context(level_xyz, o.scan_context);
                d.context_seconds[t] += since(start);
            }
            const std::size_t finished = ++done;
            if (o.progress) {
                std::lock_guard lock(progress_lock);
                o.progress(finished, n);
            }
        }
    });
}

// The place-cell rates of a network learning online along the sequence, one step per scan: each scan
// is described by the network as it was when the scan arrived.
analysis::RowMatrixXf learn_along(const RateStream& s, std::uint64_t seed) {
    PlaceCellNetwork net(s.model.bvc.n_cells(), s.model.place, seed);
    const auto cells = static_cast<std::size_t>(s.model.bvc.n_cells());
    const auto n = static_cast<Eigen::Index>(s.rates.rows());
    analysis::RowMatrixXf place(n, s.model.place.n_place);
    for (Eigen::Index i = 0; i < n; ++i) {
        if (i % 256 == 0) poll_cancel();
        const auto rates = std::span<const double>(s.rates_double).subspan(static_cast<std::size_t>(i) * cells, cells);
        const auto v = net.step(rates, true);
        for (std::size_t c = 0; c < v.size(); ++c) place(i, static_cast<Eigen::Index>(c)) = v[c];
    }
    return place;
}

double total(const std::vector<double>& v) { return std::accumulate(v.begin(), v.end(), 0.0); }

}  // namespace

PlaceRecognitionOutcome run_place_recognition(const ScanSequence& seq, const std::vector<DescriptorSpec>& descriptors,
                                              const PlaceRecognitionOptions& o) {
    o.validate();
    if (descriptors.empty()) throw InputError("no descriptor given");
    const std::size_t n = seq.size();
    PlaceRecognitionOutcome out;
    out.sequence = seq.name();
    const analysis::QueryPlan plan = query_plan(seq, o);
    out.protocol = plan.protocol;
    out.times = scan_times(seq);
    out.positions.resize(static_cast<Eigen::Index>(n), 3);
    out.heading.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        const auto& pose = seq.pose(i);
        out.positions.row(static_cast<Eigen::Index>(i)) = pose.translation().transpose();
        out.heading[i] = heading_of(pose.linear());
    }
    out.drift = heading_drift(out.times, deg_to_rad(o.drift_deg_per_sqrt_min), o.seed);

    Descriptions d = descriptions_for(descriptors);
    const std::size_t cores = thread_count(o.threads);
    const auto start = Clock::now();
    describe_scans(seq, out.heading, out.drift, o, std::max<std::size_t>(1, std::min(n, cores)), d);
    out.describe_wall_seconds = since(start);
    out.read_seconds = total(d.read_seconds);

    for (std::size_t k = 0; k < descriptors.size(); ++k) {
        const DescriptorSpec& spec = descriptors[k];
        DescriptorOutcome r;
        r.spec = spec;
        auto begin = Clock::now();
        std::unique_ptr<analysis::MatchIndex> index;
        if (!d.stream_of[k]) {
            r.describe_seconds = total(d.context_seconds);
            index = std::make_unique<analysis::ScanContextIndex>(d.contexts, o.scan_context.candidates);
        } else if (const RateStream& s = d.streams[*d.stream_of[k]]; spec.kind->learns) {
            const analysis::RowMatrixXf place = learn_along(s, o.seed);
            r.describe_seconds = total(s.seconds) + since(begin);
            begin = Clock::now();
            index = std::make_unique<analysis::RateMatchIndex>(place, analysis::QueryTurns{}, o.threads);
        } else {
            r.describe_seconds = total(s.seconds);
            analysis::QueryTurns turns;  // the heading-free match turns the query over the BVC directions
            if (spec.kind->heading == HeadingUse::free)
                turns = {s.model.bvc.n_dir, static_cast<std::size_t>(s.model.bvc.n_per_axis)};
            index = std::make_unique<analysis::RateMatchIndex>(s.rates, turns, o.threads);
        }
        r.result = analysis::evaluate(*index, plan, out.positions, o.loop.revisit_m);
        r.search_seconds = since(begin);
        out.descriptors.push_back(std::move(r));
    }
    return out;
}

}  // namespace bvc3d

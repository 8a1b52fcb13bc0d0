#include "bvc3d/analysis/place_recognition.hpp"

#include <nanoflann.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numeric>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d::analysis {

const params::Table<LoopClosureParams>& LoopClosureParams::table() {
    using namespace params;
    static const Table<LoopClosureParams> t(
        "place recognition",
        {integer("exclude_scans", &LoopClosureParams::exclude_scans, closed(0, 1000000000),
                 "sequential protocol: scan i matches scan j only when i - j > this"),
         real("exclude_seconds", &LoopClosureParams::exclude_seconds, at_least(0),
              "s, sequential protocol: and, when scans carry times, only when t_i - t_j > this"),
         real("revisit_m", &LoopClosureParams::revisit_m, above(0),
              "m, a match this close (horizontally) is right; a query with a candidate this close has a revisit")});
    return t;
}

ScanSpan parse_scan_span(const std::string& text, const std::string& what) {
    const auto colon = text.find(':');
    auto whole = [&](std::string_view s, std::size_t& out) {
        const auto* end = s.data() + s.size();
        return !s.empty() && std::from_chars(s.data(), end, out).ptr == end;
    };
    ScanSpan span;
    if (colon == std::string::npos || !whole(std::string_view(text).substr(0, colon), span.first) ||
        !whole(std::string_view(text).substr(colon + 1), span.last))
        throw InputError(what + " '" + text + "' must be A:B, the first and last scan (whole numbers, both included)");
    if (span.first > span.last)
        throw InputError(what + " '" + text + "' is empty: its first scan comes after its last");
    return span;
}

QueryPlan sequential_plan(std::size_t n, std::span<const double> times, const LoopClosureParams& p) {
    p.validate();
    const bool timed = !times.empty();
    if (timed && times.size() != n) throw InputError("sequential protocol: one time per scan");
    for (std::size_t i = 1; timed && i < n; ++i)
        if (!(times[i] > times[i - 1]))
            throw InputError("sequential protocol: scan " + std::to_string(i) + "'s time does not follow scan " +
                             std::to_string(i - 1) + "'s");
    const auto scans = static_cast<std::size_t>(p.exclude_scans);
    QueryPlan plan;
    plan.protocol = "sequential";
    std::size_t end = 0;  // scans [0, end) are old enough for query i (both windows grow with i)
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t by_index = i > scans ? i - scans : 0;  // j < i - exclude_scans
        while (end < by_index && (!timed || times[i] - times[end] > p.exclude_seconds)) ++end;
        if (end == 0) continue;
        plan.queries.push_back(i);
        plan.ranges.push_back({0, end});
    }
    if (plan.queries.empty()) {
        std::string window = std::to_string(p.exclude_scans) + " scans";
        if (timed) window += " and " + format_number(p.exclude_seconds) + " s";
        throw InputError("the exclusion window (" + window + ") is as long as the sequence (" + std::to_string(n) +
                         " scans" + (timed && n ? " over " + format_number(times[n - 1] - times[0]) + " s" : "") +
                         "): no scan has an older one to match");
    }
    return plan;
}

QueryPlan split_plan(std::size_t n, const ScanSpan& database, const ScanSpan& queries) {
    auto inside = [&](const ScanSpan& s, const char* what) {
        if (s.first > s.last) throw InputError(std::string(what) + " is empty");
        if (s.last >= n)
            throw InputError(std::string(what) + " " + std::to_string(s.first) + ":" + std::to_string(s.last) +
                             " reaches past the last scan (" + std::to_string(n) +
                             " scans, 0:" + std::to_string(n ? n - 1 : 0) + ")");
    };
    inside(database, "--database");
    inside(queries, "--queries");
    if (database.contains(queries.first) || database.contains(queries.last) || queries.contains(database.first))
        throw InputError("the split overlaps itself: --database " + std::to_string(database.first) + ":" +
                         std::to_string(database.last) + " and --queries " + std::to_string(queries.first) + ":" +
                         std::to_string(queries.last) + " share scans");
    QueryPlan plan;
    plan.protocol = "split";
    for (std::size_t i = queries.first; i <= queries.last; ++i) {
        plan.queries.push_back(i);
        plan.ranges.push_back({database.first, database.last + 1});
    }
    return plan;
}

// ----------------------------------------------------------------------------------------- rates

RateMatchIndex::RateMatchIndex(const Eigen::Ref<const RowMatrixXf>& rates, QueryTurns turns, int threads)
    : index_(rates), turns_(turns), threads_(threads) {}

std::vector<MatchIndex::Match> RateMatchIndex::best(const QueryPlan& plan) const {
    const auto found = index_.best_of_rows(plan.queries, plan.ranges, turns_, threads_);
    std::vector<Match> out(found.size());
    for (std::size_t k = 0; k < found.size(); ++k)
        if (found[k].index >= 0) out[k] = {found[k].index, 1.0 - found[k].similarity};
    return out;
}

// ---------------------------------------------------------------------------------- Scan Context

namespace {

// The ring keys as nanoflann's dataset: the first `count` of them (the tree adds them as they become
// candidates; its constructor adds those there are already).
struct RingKeys {
    const std::vector<ScanContext>* sc;
    const std::size_t* count;
    std::size_t kdtree_get_point_count() const { return *count; }
    double kdtree_get_pt(std::size_t i, std::size_t d) const { return (*sc)[i].ring_key[d]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
        return false;
    }
};
using RingKeyTree = nanoflann::KDTreeSingleIndexDynamicAdaptor<nanoflann::L2_Simple_Adaptor<double, RingKeys>, RingKeys,
                                                               -1, std::uint32_t>;

}  // namespace

ScanContextIndex::ScanContextIndex(std::vector<ScanContext> descriptors, int candidates)
    : descriptors_(std::move(descriptors)), candidates_(candidates) {
    if (candidates < 1) throw InputError("Scan Context: candidates must be at least 1");
    for (const auto& d : descriptors_)
        if (d.rings != descriptors_.front().rings || d.sectors != descriptors_.front().sectors)
            throw InputError("Scan Context: descriptors of different sizes");
}

std::vector<MatchIndex::Match> ScanContextIndex::best(const QueryPlan& plan) const {
    std::vector<Match> out(plan.queries.size());
    if (plan.queries.empty() || descriptors_.empty()) return out;
    const std::size_t first = plan.ranges.front().first;
    std::vector<std::size_t> order(plan.queries.size());
    std::iota(order.begin(), order.end(), 0);
    for (const auto& r : plan.ranges)
        if (r.first != first) throw InputError("Scan Context: a plan's ranges must start at the same scan");
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return plan.ranges[a].end < plan.ranges[b].end; });
    // Only the scans of the ranges are in the tree: it indexes the slice [first, ...) of the keys.
    const std::vector<ScanContext> slice(descriptors_.begin() + static_cast<std::ptrdiff_t>(first), descriptors_.end());
    std::size_t in_tree = 0;
    const RingKeys keys{&slice, &in_tree};
    const auto rings = static_cast<int>(descriptors_.front().rings);
    RingKeyTree tree(rings, keys, nanoflann::KDTreeSingleIndexAdaptorParams(10),
                     std::max<std::size_t>(slice.size(), 1));
    std::size_t added = first;  // scans [first, added) are in the tree
    const auto k = static_cast<std::size_t>(candidates_);
    std::vector<std::uint32_t> found(k);
    std::vector<double> dist2(k);
    for (const std::size_t q : order) {
        const std::size_t end = plan.ranges[q].end;
        if (end > added) {
            in_tree = end - first;
            tree.addPoints(static_cast<std::uint32_t>(added - first), static_cast<std::uint32_t>(end - first - 1));
            added = end;
        }
        if (end <= first) continue;
        nanoflann::KNNResultSet<double, std::uint32_t> result(k);
        result.init(found.data(), dist2.data());
        // Only scans below `end` are in the tree (ranges are visited in increasing order).
        tree.findNeighbors(result, descriptors_[plan.queries[q]].ring_key.data(), nanoflann::SearchParams());
        Match best;
        for (std::size_t c = 0; c < result.size(); ++c) {
            const std::size_t j = first + found[c];
            const double d = scan_context_distance(descriptors_[plan.queries[q]], descriptors_[j]).distance;
            if (best.index < 0 || d < best.distance || (d == best.distance && static_cast<long>(j) < best.index))
                best = {static_cast<long>(j), d};
        }
        out[q] = best;
    }
    return out;
}

// ------------------------------------------------------------------------------------- metrics

PrCurve precision_recall(std::span<const double> distance, std::span<const char> correct, std::size_t revisits) {
    if (distance.size() != correct.size()) throw InputError("precision-recall: one 'correct' per distance");
    for (std::size_t i = 0; i < distance.size(); ++i)
        if (std::isnan(distance[i])) throw InputError("precision-recall: distance " + std::to_string(i) + " is NaN");
    std::vector<std::size_t> order(distance.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return distance[a] < distance[b]; });
    const double denominator = revisits ? static_cast<double>(revisits) : std::numeric_limits<double>::quiet_NaN();
    PrCurve c;
    std::size_t tp = 0;
    for (std::size_t k = 0; k < order.size(); ++k) {
        tp += correct[order[k]] ? 1 : 0;
        // A threshold at each distinct distance: the last query of a run of equal distances.
        if (k + 1 < order.size() && distance[order[k + 1]] == distance[order[k]]) continue;
        c.threshold.push_back(distance[order[k]]);
        c.precision.push_back(static_cast<double>(tp) / static_cast<double>(k + 1));
        c.recall.push_back(static_cast<double>(tp) / denominator);
    }
    std::reverse(c.threshold.begin(), c.threshold.end());
    std::reverse(c.precision.begin(), c.precision.end());
    std::reverse(c.recall.begin(), c.recall.end());
    c.threshold.push_back(-std::numeric_limits<double>::infinity());
    c.precision.push_back(1.0);
    c.recall.push_back(0.0);
    return c;
}

PrSummary summarize(const QueryRows& rows, const PrCurve& curve) {
    PrSummary s;
    s.queries = rows.query.size();
    s.revisits = static_cast<std::size_t>(std::count(rows.has_revisit.begin(), rows.has_revisit.end(), 1));
    s.correct = static_cast<std::size_t>(std::count(rows.correct.begin(), rows.correct.end(), 1));
    std::vector<double> m;
    for (std::size_t i = 0; i < rows.query.size(); ++i)
        if (rows.has_revisit[i]) m.push_back(rows.match_m[i]);
    if (!m.empty()) {
        std::sort(m.begin(), m.end());
        const std::size_t h = m.size() / 2;
        s.median_match_m = m.size() % 2 ? m[h] : 0.5 * (m[h - 1] + m[h]);
    }
    if (s.revisits == 0) return s;
    s.recall_at_1 = static_cast<double>(s.correct) / static_cast<double>(s.revisits);
    s.f1_max = 0;
    for (std::size_t k = 0; k < curve.recall.size(); ++k) {
        const double p = curve.precision[k], r = curve.recall[k];
        if (p + r > 0) s.f1_max = std::max(s.f1_max, 2 * p * r / (p + r));
    }
    // Trapezoids between consecutive points (recall decreases along the curve to its end at 0).
    s.auc = 0;
    for (std::size_t k = 0; k + 1 < curve.recall.size(); ++k)
        s.auc += (curve.recall[k] - curve.recall[k + 1]) * (curve.precision[k] + curve.precision[k + 1]) / 2;
    return s;
}

// ------------------------------------------------------------------------------------- evaluate

namespace {

struct PlanePoints {
    const Eigen::Ref<const Points>* p;
    std::size_t kdtree_get_point_count() const { return static_cast<std::size_t>(p->rows()); }
    double kdtree_get_pt(std::size_t i, std::size_t d) const {
        return (*p)(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(d));
    }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
        return false;
    }
};
using PlaneTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PlanePoints>, PlanePoints, 2,
                                                      std::uint32_t>;

double horizontal(const Eigen::Ref<const Points>& p, std::size_t a, std::size_t b) {
    const auto i = static_cast<Eigen::Index>(a), j = static_cast<Eigen::Index>(b);
    return std::hypot(p(i, 0) - p(j, 0), p(i, 1) - p(j, 1));
}

}  // namespace

PlaceRecognitionResult evaluate(const MatchIndex& index, const QueryPlan& plan,
                                const Eigen::Ref<const Points>& positions, double revisit_m) {
    const std::size_t n = index.size();
    if (static_cast<std::size_t>(positions.rows()) != n || positions.cols() < 2)
        throw InputError("place recognition: one position (x, y[, z]) per scan");
    if (!positions.allFinite()) throw InputError("place recognition: positions must be finite");
    if (plan.queries.size() != plan.ranges.size()) throw InputError("place recognition: one range per query");
    const auto matches = index.best(plan);

    const PlanePoints pts{&positions};
    PlaneTree tree(2, pts, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    tree.buildIndex();
    // Searched a little wider than the radius; the exact test is on the distance itself.
    const double search2 = revisit_m * revisit_m * (1 + 1e-9) + 1e-12;
    std::vector<std::pair<std::uint32_t, double>> near;

    PlaceRecognitionResult r;
    QueryRows& rows = r.rows;
    for (std::size_t k = 0; k < plan.queries.size(); ++k) {
        const std::size_t q = plan.queries[k];
        const auto& range = plan.ranges[k];
        const double at[2] = {positions(static_cast<Eigen::Index>(q), 0), positions(static_cast<Eigen::Index>(q), 1)};
        tree.radiusSearch(at, search2, near, nanoflann::SearchParams(32, 0, false));
        bool revisit = false;
        for (const auto& [j, d2] : near)
            if (j >= range.first && j < range.end && horizontal(positions, q, j) <= revisit_m) revisit = true;
        const MatchIndex::Match& m = matches[k];
        rows.query.push_back(q);
        rows.match.push_back(m.index);
        rows.distance.push_back(m.distance);
        const double metres = m.index >= 0 ? horizontal(positions, q, static_cast<std::size_t>(m.index))
                                           : std::numeric_limits<double>::quiet_NaN();
        rows.match_m.push_back(metres);
        rows.has_revisit.push_back(revisit);
        rows.correct.push_back(m.index >= 0 && metres <= revisit_m);
    }
    r.curve =
        precision_recall(rows.distance, rows.correct,
                         static_cast<std::size_t>(std::count(rows.has_revisit.begin(), rows.has_revisit.end(), 1)));
    r.summary = summarize(rows, r.curve);
    return r;
}

}  // namespace bvc3d::analysis

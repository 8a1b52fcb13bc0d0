#pragma once
// Place recognition, the field's protocol (docs/place-recognition.md): which scans query which,
// each query's best match by a descriptor's distance, whether the query has a revisit and whether
// its match is right, and the metrics (recall@1, the precision-recall curve, its area, F1max).
// Takes: scan positions (and times), and a descriptor's search over the scans (MatchIndex: rate
// vectors by cosine, or Scan Context). Gives: one row per query and the summary.
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "bvc3d/analysis/cosine_search.hpp"
#include "bvc3d/analysis/types.hpp"
#include "bvc3d/bvc/scan_context.hpp"
#include "bvc3d/core/params.hpp"

namespace bvc3d::analysis {

// The sequential protocol's windows and the revisit radius of both protocols.
struct LoopClosureParams {
    int exclude_scans = 50;         // scan i may match scan j only when i - j > exclude_scans
    double exclude_seconds = 30.0;  // ... and, when the scans carry times, t_i - t_j > exclude_seconds
    double revisit_m = 5.0;         // m: a match within this horizontal distance is right

    static const params::Table<LoopClosureParams>& table();
    void validate() const { table().check(*this); }
};

// Scans first..last, both included (scan numbers as a recording counts them).
struct ScanSpan {
    std::size_t first = 0, last = 0;
    std::size_t size() const { return last - first + 1; }
    bool contains(std::size_t i) const { return i >= first && i <= last; }
};
// "A:B" (both included); InputError naming `what` when it is not two whole numbers with A <= B.
ScanSpan parse_scan_span(const std::string& text, const std::string& what);

// Which scans query which: query i may match the scans [range.first, range.end).
struct QueryPlan {
    std::string protocol;  // "sequential" or "split"
    std::vector<std::size_t> queries;
    std::vector<CosineIndex::Range> ranges;
};
// Sequential loop closure over n scans: scan i queries the scans older than both windows (the time
// window only when `times` has one time per scan). Scans with nothing old enough do not query.
// InputError when a window leaves no scan anything to match (it is as long as the sequence).
QueryPlan sequential_plan(std::size_t n, std::span<const double> times, const LoopClosureParams& params);
// Database/query split: every scan of `queries` queries the scans of `database`. InputError for
// spans outside the n scans or overlapping each other.
QueryPlan split_plan(std::size_t n, const ScanSpan& database, const ScanSpan& queries);

// A descriptor's search: the best match of each query among its range, and the distance to it.
class MatchIndex {
public:
    virtual ~MatchIndex() = default;
    struct Match {
        long index = -1;  // the matched scan, -1 when the range is empty
        double distance = std::numeric_limits<double>::quiet_NaN();
    };
    virtual std::size_t size() const = 0;  // scans
    virtual std::vector<Match> best(const QueryPlan& plan) const = 0;
};

// Rate vectors (one row per scan), distance 1 − cos; ties go to the older scan. With turns, each
// query is also compared turned along its cyclic axis (a heading-free BVC match) and the best turn
// counts.
class RateMatchIndex : public MatchIndex {
public:
    explicit RateMatchIndex(const Eigen::Ref<const RowMatrixXf>& rates, QueryTurns turns = {}, int threads = 0);
    std::size_t size() const override { return index_.size(); }
    std::vector<Match> best(const QueryPlan& plan) const override;

private:
    CosineIndex index_;
    QueryTurns turns_;
    int threads_;
};

// Scan Context: the `candidates` scans of the range whose ring keys are nearest (a k-d tree,
// nanoflann), compared in full; the smallest distance wins (ties: the older scan). Queries of a plan
// must share their ranges' first scan (both protocols do); the tree grows as the ranges do.
class ScanContextIndex : public MatchIndex {
public:
    ScanContextIndex(std::vector<ScanContext> descriptors, int candidates);
    std::size_t size() const override { return descriptors_.size(); }
    std::vector<Match> best(const QueryPlan& plan) const override;

private:
    std::vector<ScanContext> descriptors_;
    int candidates_;
};

// One row per query (as queries.csv has them).
struct QueryRows {
    std::vector<std::size_t> query;
    std::vector<long> match;
    std::vector<double> distance, match_m;  // the descriptor's distance; the match's horizontal distance, m
    std::vector<char> has_revisit, correct;
};

// The precision-recall curve over thresholds τ on the distance: a query is predicted a revisit when
// its distance <= τ; a true positive when its match is right, else a false positive. Precision =
// TP / predicted, recall = TP / queries with a revisit. As scikit-learn's precision_recall_curve
// lists it (scores = −distance): one point per distinct distance, in decreasing order of threshold
// (so of recall), then the end point (recall 0, precision 1; threshold −inf). scikit-learn's recall
// divides by the right matches, this one by the revisits.
struct PrCurve {
    std::vector<double> threshold, precision, recall;
};

struct PrSummary {
    std::size_t queries = 0, revisits = 0, correct = 0;
    double recall_at_1 = std::numeric_limits<double>::quiet_NaN();     // right matches / revisits
    double f1_max = std::numeric_limits<double>::quiet_NaN();          // max 2PR / (P + R) over the curve
    double auc = std::numeric_limits<double>::quiet_NaN();             // trapezoids under the curve
    double median_match_m = std::numeric_limits<double>::quiet_NaN();  // over the queries with a revisit
};

// The curve and summary from each query's distance, whether its match is right, and whether it has
// a revisit. Without revisits the recall (hence recall@1, F1max, AUC) is undefined: NaN.
PrCurve precision_recall(std::span<const double> distance, std::span<const char> correct, std::size_t revisits);
PrSummary summarize(const QueryRows& rows, const PrCurve& curve);

struct PlaceRecognitionResult {
    QueryRows rows;
    PrCurve curve;
    PrSummary summary;
};

// Runs a plan through an index: each query's best match, its distance in metres (x, y of
// `positions`, one row per scan), whether a scan of its range lies within revisit_m, and the metrics.
PlaceRecognitionResult evaluate(const MatchIndex& index, const QueryPlan& plan,
                                const Eigen::Ref<const Points>& positions, double revisit_m);

}  // namespace bvc3d::analysis

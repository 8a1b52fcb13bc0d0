// Place recognition's search (docs/performance.md#place-recognition): the best match of a query among
// 10^5 templates of 960 rates (a growing map), by the blocked search (analysis/cosine_search) in
// batches of 1, 16 and 256 queries on 1 and 2 threads, beside a plain search in the same run (Eigen's
// matrix-vector product of the unit templates with each query, then the largest). Time per query:
// the benchmark's time divided by the batch (items per second = queries per second). Scan Context's
// descriptor and one query's search (10 candidates among 4 500 scans) beside it.
#include <benchmark/benchmark.h>

#include <random>

#include "bvc3d/analysis/cosine_search.hpp"
#include "bvc3d/analysis/place_recognition.hpp"
#include "bvc3d/bvc/scan_context.hpp"

using namespace bvc3d;
using namespace bvc3d::analysis;

namespace {

constexpr Eigen::Index templates = 100000, cells = 960;

// BVC-like rates: non-negative, most of each row small.
RowMatrixXf rates(Eigen::Index rows, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::exponential_distribution<float> e(8.0f);
    RowMatrixXf m(rows, cells);
    for (Eigen::Index i = 0; i < rows; ++i)
        for (Eigen::Index k = 0; k < cells; ++k) m(i, k) = std::min(0.5f, e(rng));
    return m;
}

const CosineIndex& index() {
    static const CosineIndex i(rates(templates, 1));
    return i;
}

void BM_BlockedSearch(benchmark::State& state) {
    const auto batch = static_cast<Eigen::Index>(state.range(0));
    const int threads = static_cast<int>(state.range(1));
    const RowMatrixXf q = rates(batch, 2);
    const std::vector<CosineIndex::Range> ranges(static_cast<std::size_t>(batch), {0, templates});
    const CosineIndex& idx = index();
    for (auto _ : state) benchmark::DoNotOptimize(idx.best(q, ranges, {}, threads));
    state.SetItemsProcessed(state.iterations() * batch);
    state.counters["ms_per_query"] = benchmark::Counter(
        static_cast<double>(batch) * 1e-3, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_BlockedSearch)
    ->ArgNames({"batch", "threads"})
    ->Args({1, 1})
    ->Args({1, 2})
    ->Args({16, 2})
    ->Args({256, 1})
    ->Args({256, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The plain search: unit templates times the unit query (Eigen, float), the largest.
void BM_PlainSearch(benchmark::State& state) {
    static const RowMatrixXf t = [] {
        RowMatrixXf m = rates(templates, 1);
        m.rowwise().normalize();
        return m;
    }();
    Eigen::VectorXf q = rates(1, 2).row(0).transpose();
    q.normalize();
    for (auto _ : state) {
        const Eigen::VectorXf s = t * q;
        Eigen::Index arg;
        benchmark::DoNotOptimize(s.maxCoeff(&arg));
    }
    state.SetItemsProcessed(state.iterations());
    state.counters["ms_per_query"] =
        benchmark::Counter(1e-3, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_PlainSearch)->Unit(benchmark::kMillisecond)->UseRealTime();

// Scan Context of a KITTI-BEV-sized scan (1 500 points within 35 m) and the sequential queries of the
// last 100 of 4 500 scans (the k-d tree built once for them): ten ring-key candidates each, compared
// over the 60 shifts.
std::vector<double> street_points(std::mt19937& rng) {
    std::uniform_real_distribution<double> xy(-25, 25), z(-1.7, 2.3);
    std::vector<double> p;
    for (int i = 0; i < 1500; ++i) p.insert(p.end(), {xy(rng), xy(rng), z(rng)});
    return p;
}

void BM_ScanContextDescriptor(benchmark::State& state) {
    std::mt19937 rng(3);
    const auto p = street_points(rng);
    for (auto _ : state) benchmark::DoNotOptimize(scan_context(p));
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_ScanContextDescriptor)->Unit(benchmark::kMicrosecond);

void BM_ScanContextQuery(benchmark::State& state) {
    std::mt19937 rng(4);
    std::vector<ScanContext> sc;
    for (int i = 0; i < 4501; ++i) sc.push_back(scan_context(street_points(rng)));
    const ScanContextIndex index(sc, 10);
    QueryPlan plan;
    for (std::size_t q = 4401; q <= 4500; ++q) {
        plan.queries.push_back(q);
        plan.ranges.push_back({0, q - 50});
    }
    for (auto _ : state) benchmark::DoNotOptimize(index.best(plan));
    state.SetItemsProcessed(state.iterations() * 100);
}
BENCHMARK(BM_ScanContextQuery)->Unit(benchmark::kMillisecond);

}  // namespace

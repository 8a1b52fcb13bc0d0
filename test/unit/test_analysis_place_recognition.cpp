// Place recognition's search (docs/place-recognition.md): the blocked cosine search against a plain
// double-precision search, Scan Context's k-d tree against the ten nearest ring keys found by
// sorting, and the protocol's windows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "bvc3d/analysis/cosine_kernels.hpp"
#include "bvc3d/analysis/cosine_search.hpp"
#include "bvc3d/analysis/place_recognition.hpp"
#include "bvc3d/core/error.hpp"

using namespace bvc3d;
using namespace bvc3d::analysis;

namespace {

RowMatrixXf random_rows(std::size_t n, std::size_t d, std::uint32_t seed, double zero = 0.5) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0, 1);
    RowMatrixXf m(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(d));
    for (Eigen::Index i = 0; i < m.rows(); ++i)
        for (Eigen::Index k = 0; k < m.cols(); ++k) m(i, k) = u(rng) < zero ? 0.0f : u(rng);
    return m;
}

double cosine(const RowMatrixXf& a, Eigen::Index i, const RowMatrixXf& b, Eigen::Index j) {
    const Eigen::VectorXd x = a.row(i).cast<double>(), y = b.row(j).cast<double>();
    const double n = x.norm() * y.norm();
    return n > 0 ? x.dot(y) / n : 0.0;
}

// Row `i` of `m` turned by `s` steps of `inner` values along `turns` (what QueryTurns means).
RowMatrixXf turned(const RowMatrixXf& m, Eigen::Index i, int turns, int inner, int s) {
    RowMatrixXf out(1, m.cols());
    const int period = turns * inner;
    for (int outer = 0; outer < m.cols(); outer += period)
        for (int k = 0; k < turns; ++k)
            for (int c = 0; c < inner; ++c) out(0, outer + ((k + s) % turns) * inner + c) = m(i, outer + k * inner + c);
    return out;
}

}  // namespace

TEST(PlaceRecognition, BlockedSearchIsThePlainSearch) {
    // Sizes that are not multiples of the kernel's tiles (4 queries x 3 templates, 16 floats).
    const RowMatrixXf templates = random_rows(701, 37, 1), queries = random_rows(150, 37, 2);
    std::vector<CosineIndex::Range> ranges;
    std::mt19937 rng(3);
    for (int q = 0; q < 150; ++q) {
        const std::size_t a = rng() % 701, b = rng() % 702;
        ranges.push_back({std::min(a, b), std::max(a, b)});
    }
    ranges[5] = {7, 7};  // empty
    const CosineIndex index(templates);
    const auto one = index.best(queries, ranges, {}, 1), three = index.best(queries, ranges, {}, 3);
    for (std::size_t q = 0; q < ranges.size(); ++q) {
        EXPECT_EQ(one[q].index, three[q].index);
        EXPECT_EQ(one[q].similarity, three[q].similarity);  // the same bits whatever the threads
        if (ranges[q].first == ranges[q].end) {
            EXPECT_EQ(one[q].index, -1);
            continue;
        }
        double best = -1;
        long arg = -1;
        for (std::size_t j = ranges[q].first; j < ranges[q].end; ++j) {
            const double c = cosine(queries, static_cast<Eigen::Index>(q), templates, static_cast<Eigen::Index>(j));
            if (c > best) best = c, arg = static_cast<long>(j);
        }
        EXPECT_NEAR(one[q].similarity, best, 2e-6) << q;
        // Float rounding may swap near-ties only.
        if (one[q].index != arg) {
            EXPECT_NEAR(cosine(queries, static_cast<Eigen::Index>(q), templates, one[q].index), best, 2e-6);
        }
    }
}

TEST(PlaceRecognition, TheKernelGivesTheSameBitsOnEveryInstructionSet) {
    // 4 queries x 7 templates of 48 floats (3 blocks of 16 lanes): each dot product against a double
    // sum, and the instruction sets this CPU runs against each other, bit for bit.
    const std::size_t stride = 48, n = 7;
    const RowMatrixXf q = random_rows(4, stride, 10, 0.2), t = random_rows(n, stride, 11, 0.2);
    std::vector<std::vector<float>> outs;
    std::vector<simd::Isa> isas{simd::Isa::baseline};
#if BVC3D_HAVE_DISPATCH
    if (__builtin_cpu_supports("x86-64-v3")) isas.push_back(simd::Isa::v3);
    if (__builtin_cpu_supports("x86-64-v4")) isas.push_back(simd::Isa::v4);
#endif
    for (const simd::Isa isa : isas) {
        std::vector<float> out(4 * n);
        kernels::dots(q.data(), 4, t.data(), n, stride, out.data(), n, isa);
        std::vector<float> three(4 * n, -1.0f);  // fewer rows: the same numbers, nothing written past them
        kernels::dots(q.data(), 3, t.data(), n, stride, three.data(), n, isa);
        EXPECT_TRUE(std::equal(three.begin(), three.begin() + 3 * n, out.begin()));
        EXPECT_TRUE(std::all_of(three.begin() + 3 * n, three.end(), [](float x) { return x == -1.0f; }));
        for (Eigen::Index a = 0; a < 4; ++a)
            for (Eigen::Index j = 0; j < static_cast<Eigen::Index>(n); ++j)
                EXPECT_NEAR(out[static_cast<std::size_t>(a) * n + static_cast<std::size_t>(j)],
                            q.row(a).cast<double>().dot(t.row(j).cast<double>()), 1e-5);
        outs.push_back(out);
    }
    for (const auto& out : outs) EXPECT_EQ(out, outs.front());
}

TEST(PlaceRecognition, FewQueriesSplitTheTemplatesBetweenThreads) {
    // Two queries, 9000 templates: the templates are searched in chunks, one per thread, and merged.
    RowMatrixXf templates = random_rows(9000, 24, 8);
    const RowMatrixXf queries = random_rows(2, 24, 9);
    templates.row(2000) = queries.row(0);
    templates.row(8999) = queries.row(0);  // a tie later on: the earlier template wins
    const std::vector<CosineIndex::Range> ranges{{0, 9000}, {100, 8800}};
    const CosineIndex index(templates);
    const auto one = index.best(queries, ranges, {}, 1), four = index.best(queries, ranges, {}, 4);
    EXPECT_EQ(one[0].index, 2000);
    EXPECT_EQ(four[0].index, 2000);  // chunk 0 of 2 beats chunk 1
    EXPECT_EQ(one[1].index, four[1].index);
    EXPECT_EQ(one[1].similarity, four[1].similarity);
    double best = -1;
    for (Eigen::Index j = 100; j < 8800; ++j) best = std::max(best, cosine(queries, 1, templates, j));
    EXPECT_NEAR(four[1].similarity, best, 2e-6);
    // The index's own rows as queries give what copies of them give.
    const std::vector<std::size_t> rows{2000, 3};
    const auto own = index.best_of_rows(rows, ranges, {}, 4);
    EXPECT_EQ(own[0].index, 2000);
    EXPECT_EQ(own[1].index, index.best(templates.middleRows(3, 1), std::span(ranges).subspan(1), {}, 4)[0].index);
}

TEST(PlaceRecognition, TiesGoToTheOlderScanAndZeroRowsHaveCosineZero) {
    RowMatrixXf t = random_rows(9, 20, 4);
    t.row(6) = t.row(2) * 3.0f;  // the same direction: the same cosine with anything
    t.row(4).setZero();
    const CosineIndex index(t);
    RowMatrixXf q(2, 20);
    q.row(0) = t.row(2);
    q.row(1).setZero();
    const std::vector<CosineIndex::Range> ranges{{0, 9}, {3, 9}};
    const auto found = index.best(q, ranges);
    EXPECT_EQ(found[0].index, 2);
    EXPECT_NEAR(found[0].similarity, 1.0, 1e-6);
    EXPECT_EQ(found[1].index, 3);  // every cosine 0: the first of the range
    EXPECT_EQ(found[1].similarity, 0.0);
}

TEST(PlaceRecognition, TurnedQueriesMatchTheirBestTurn) {
    const int turns = 8, inner = 5;
    const RowMatrixXf t = random_rows(300, 2 * turns * inner, 5, 0.2), q = random_rows(40, 2 * turns * inner, 6, 0.2);
    std::vector<CosineIndex::Range> ranges(40, {10, 290});
    const auto found = CosineIndex(t).best(q, ranges, {turns, inner}, 2);
    for (Eigen::Index i = 0; i < q.rows(); ++i) {
        double best = -1;
        long arg = -1;
        int turn = -1;
        for (std::size_t j = 10; j < 290; ++j)
            for (int s = 0; s < turns; ++s) {
                const double c = cosine(turned(q, i, turns, inner, s), 0, t, static_cast<Eigen::Index>(j));
                if (c > best) best = c, arg = static_cast<long>(j), turn = s;
            }
        EXPECT_NEAR(found[static_cast<std::size_t>(i)].similarity, best, 2e-6);
        if (found[static_cast<std::size_t>(i)].index == arg) {
            EXPECT_EQ(found[static_cast<std::size_t>(i)].variant, turn);
        }
    }
    // A template that is a query turned by 3 steps is found with that turn.
    RowMatrixXf t2 = t;
    t2.row(100) = turned(q, 7, turns, inner, 3);
    const auto again =
        CosineIndex(t2).best(q.middleRows(7, 1), std::vector<CosineIndex::Range>{{0, 300}}, {turns, inner});
    EXPECT_EQ(again[0].index, 100);
    EXPECT_EQ(again[0].variant, 3);
    EXPECT_NEAR(again[0].similarity, 1.0, 1e-6);
}

TEST(PlaceRecognition, ScanContextCandidatesAreTheNearestRingKeys) {
    // Random descriptors; the k-d tree's best match must be the best of the ten nearest ring keys
    // among each query's candidates, found here by sorting.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<ScanContext> sc;
    for (int i = 0; i < 400; ++i) {
        std::vector<double> bins(20 * 60);
        for (double& b : bins) b = u(rng) < 0.6 ? 0.0 : 2 + 3 * u(rng) + (i % 7);
        sc.push_back(scan_context_from_bins(20, 60, bins));
    }
    std::vector<double> times(400);
    std::iota(times.begin(), times.end(), 0.0);
    const QueryPlan plan = sequential_plan(400, times, {});
    const auto found = ScanContextIndex(sc, 10).best(plan);
    for (std::size_t k = 0; k < plan.queries.size(); ++k) {
        const std::size_t q = plan.queries[k];
        std::vector<std::pair<double, std::size_t>> near;
        for (std::size_t j = 0; j < plan.ranges[k].end; ++j) {
            double d2 = 0;
            for (int r = 0; r < 20; ++r) d2 += std::pow(sc[q].ring_key[r] - sc[j].ring_key[r], 2);
            near.push_back({d2, j});
        }
        std::sort(near.begin(), near.end());
        near.resize(std::min<std::size_t>(10, near.size()));
        double best = 1e9;
        long arg = -1;
        for (const auto& [d2, j] : near) {
            const double d = scan_context_distance(sc[q], sc[j]).distance;
            if (d < best || (d == best && static_cast<long>(j) < arg)) best = d, arg = static_cast<long>(j);
        }
        EXPECT_EQ(found[k].index, arg) << q;
        EXPECT_EQ(found[k].distance, best);
    }
    // The split: every query against the database only.
    const QueryPlan split = split_plan(400, {100, 249}, {300, 399});
    for (const auto& m : ScanContextIndex(sc, 10).best(split)) EXPECT_TRUE(m.index >= 100 && m.index <= 249);
}

TEST(PlaceRecognition, WindowsCountScansAndSeconds) {
    // Scans 0.5 s apart: 50 scans is 25 s, less than 30 s, so the time window decides (> 60 scans).
    std::vector<double> t(200);
    for (std::size_t i = 0; i < t.size(); ++i) t[i] = 0.5 * static_cast<double>(i);
    const QueryPlan p = sequential_plan(200, t, {});
    EXPECT_EQ(p.queries.front(), 61u);  // t = 30.5 s: scan 0 is older than 30 s
    for (std::size_t k = 0; k < p.queries.size(); ++k) EXPECT_EQ(p.ranges[k].end, p.queries[k] - 60);
    const QueryPlan untimed = sequential_plan(200, {}, {});
    EXPECT_EQ(untimed.queries.front(), 51u);
    EXPECT_EQ(untimed.ranges.front().end, 1u);
    EXPECT_THROW(sequential_plan(51, {}, {}), InputError);  // scan 50 is 50 scans after scan 0: not more
    EXPECT_NO_THROW(sequential_plan(52, {}, {}));
    t[7] = t[6];
    EXPECT_THROW(sequential_plan(200, t, {}), InputError);
    EXPECT_THROW(parse_scan_span("3:", "--database"), InputError);
    EXPECT_THROW(parse_scan_span("4:2", "--database"), InputError);
    EXPECT_THROW(parse_scan_span("-1:2", "--database"), InputError);
    EXPECT_EQ(parse_scan_span("0:3000", "--database").last, 3000u);
}

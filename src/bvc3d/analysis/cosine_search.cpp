#include "bvc3d/analysis/cosine_search.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include "bvc3d/analysis/cosine_kernels.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/parallel.hpp"

#if BVC3D_HAVE_DISPATCH
#include <immintrin.h>  // the kernels' intrinsics
#endif

namespace bvc3d::analysis {

namespace {

constexpr std::size_t lanes = 16;            // floats per partial sum vector (cosine_dots.inc)
constexpr std::size_t query_tile = 4;        // query rows per kernel call
constexpr std::size_t row_block = 64;        // query rows per task (a multiple of query_tile)
constexpr std::size_t template_block = 256;  // templates per pass (~1 MB of 960 floats: in L2)

// Adds the 16 lanes in order (the same order whatever holds them).
inline float sum16(const float* v) {
    float s = 0;
    for (std::size_t k = 0; k < lanes; ++k) s += v[k];
    return s;
}

// The kernel, compiled for each instruction set with fused multiply-adds (see cosine_dots.inc): FMA
// doubles what each cycle adds, and an exactly rounded fma is the same on every CPU (the baseline's
// std::fma is slow, but exact).
#if BVC3D_HAVE_DISPATCH
#pragma GCC push_options
#pragma GCC target("arch=x86-64-v4")
namespace v4 {
struct Lanes {
    __m512 v;
    static Lanes zero() { return {_mm512_setzero_ps()}; }
    static Lanes load(const float* p) { return {_mm512_loadu_ps(p)}; }
    static Lanes fma(const Lanes& a, const Lanes& b, const Lanes& c) { return {_mm512_fmadd_ps(a.v, b.v, c.v)}; }
    float sum() const {
        alignas(64) float l[16];
        _mm512_store_ps(l, v);
        return sum16(l);
    }
};
constexpr std::size_t rows_per_pass = 4;  // 12 accumulators of AVX-512's 32 registers
#include "bvc3d/analysis/cosine_dots.inc"
}  // namespace v4
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("arch=x86-64-v3")
namespace v3 {
struct Lanes {
    __m256 lo, hi;  // lanes 0-7, 8-15
    static Lanes zero() { return {_mm256_setzero_ps(), _mm256_setzero_ps()}; }
    static Lanes load(const float* p) { return {_mm256_loadu_ps(p), _mm256_loadu_ps(p + 8)}; }
    static Lanes fma(const Lanes& a, const Lanes& b, const Lanes& c) {
        return {_mm256_fmadd_ps(a.lo, b.lo, c.lo), _mm256_fmadd_ps(a.hi, b.hi, c.hi)};
    }
    float sum() const {
        alignas(32) float l[16];
        _mm256_store_ps(l, lo);
        _mm256_store_ps(l + 8, hi);
        return sum16(l);
    }
};
constexpr std::size_t rows_per_pass = 2;  // 12 of AVX2's 16 registers
#include "bvc3d/analysis/cosine_dots.inc"
}  // namespace v3
#pragma GCC pop_options
#endif
namespace baseline {
struct Lanes {
    float v[16];
    static Lanes zero() { return {}; }
    static Lanes load(const float* p) {
        Lanes l;
        std::copy_n(p, 16, l.v);
        return l;
    }
    static Lanes fma(const Lanes& a, const Lanes& b, const Lanes& c) {
        Lanes l;
        for (std::size_t k = 0; k < 16; ++k) l.v[k] = std::fma(a.v[k], b.v[k], c.v[k]);
        return l;
    }
    float sum() const { return sum16(v); }
};
constexpr std::size_t rows_per_pass = 4;
#include "bvc3d/analysis/cosine_dots.inc"
}  // namespace baseline

std::size_t padded(std::size_t dim) { return (dim + lanes - 1) / lanes * lanes; }

}  // namespace

void kernels::dots(const float* q, std::size_t rows, const float* t, std::size_t n, std::size_t stride, float* out,
                   std::size_t out_stride, simd::Isa isa) {
#if BVC3D_HAVE_DISPATCH
    if (isa == simd::Isa::v4) return v4::dots(q, rows, t, n, stride, out, out_stride);
    if (isa == simd::Isa::v3) return v3::dots(q, rows, t, n, stride, out, out_stride);
#endif
    (void)isa;  // no clones in this build: the baseline is all there is
    baseline::dots(q, rows, t, n, stride, out, out_stride);
}

void unit_rows(const Eigen::Ref<const RowMatrixXf>& rows, std::size_t stride, float* out) {
    const auto dim = static_cast<std::size_t>(rows.cols());
    for (Eigen::Index i = 0; i < rows.rows(); ++i) {
        double norm = 0;
        for (Eigen::Index k = 0; k < rows.cols(); ++k) {
            const double v = rows(i, k);
            if (!std::isfinite(v))
                throw InputError("row " + std::to_string(i) + ", column " + std::to_string(k) + " is not finite");
            norm += v * v;
        }
        norm = std::sqrt(norm);
        float* o = out + static_cast<std::size_t>(i) * stride;
        for (std::size_t k = 0; k < dim; ++k)
            o[k] = norm > 0 ? static_cast<float>(rows(i, static_cast<Eigen::Index>(k)) / norm) : 0.0f;
        std::fill(o + dim, o + stride, 0.0f);
    }
}

CosineIndex::CosineIndex(const Eigen::Ref<const RowMatrixXf>& rows)
    : n_(static_cast<std::size_t>(rows.rows())),
      dim_(static_cast<std::size_t>(rows.cols())),
      stride_(padded(static_cast<std::size_t>(rows.cols()))) {
    if (dim_ == 0) throw InputError("a cosine search needs vectors of at least one value");
    rows_.resize(n_ * stride_);
    unit_rows(rows, stride_, rows_.data());
}

std::vector<CosineIndex::Best> CosineIndex::best(const Eigen::Ref<const RowMatrixXf>& queries,
                                                 std::span<const Range> ranges, QueryTurns turns, int threads) const {
    if (static_cast<std::size_t>(queries.cols()) != dim_)
        throw InputError("queries have " + std::to_string(queries.cols()) + " values and templates " +
                         std::to_string(dim_));
    if (static_cast<std::size_t>(queries.rows()) != ranges.size())
        throw InputError("one range of templates per query: " + std::to_string(queries.rows()) + " queries, " +
                         std::to_string(ranges.size()) + " ranges");
    // The queries as unit rows, checked here (the workers must not throw).
    std::vector<float, CacheAligned<float>> unit(ranges.size() * stride_);
    unit_rows(queries, stride_, unit.data());
    return search(unit.data(), nullptr, ranges, turns, threads);
}

std::vector<CosineIndex::Best> CosineIndex::best_of_rows(std::span<const std::size_t> rows,
                                                         std::span<const Range> ranges, QueryTurns turns,
                                                         int threads) const {
    if (rows.size() != ranges.size())
        throw InputError("one range of templates per query: " + std::to_string(rows.size()) + " queries, " +
                         std::to_string(ranges.size()) + " ranges");
    for (const std::size_t r : rows)
        if (r >= n_) throw InputError("query row " + std::to_string(r) + " is not in the index");
    return search(nullptr, rows.data(), ranges, turns, threads);
}

std::vector<CosineIndex::Best> CosineIndex::search(const float* unit, const std::size_t* query_rows,
                                                   std::span<const Range> ranges, QueryTurns turns, int threads) const {
    if (turns.turns < 1 || turns.inner < 1 || dim_ % (static_cast<std::size_t>(turns.turns) * turns.inner) != 0)
        throw InputError("query turns of " + std::to_string(turns.turns) + " steps of " + std::to_string(turns.inner) +
                         " values do not divide vectors of " + std::to_string(dim_));
    for (const Range& r : ranges)
        if (r.first > r.end || r.end > n_) throw InputError("a query's range of templates lies outside the index");
    auto query = [&](std::size_t q) {
        return query_rows ? rows_.data() + query_rows[q] * stride_ : unit + q * stride_;
    };

    // Work items: blocks of query rows (a query's turns are rows of their own) × chunks of the
    // templates, so that a few queries still keep every thread busy. Chunks are searched in order
    // of their templates and merged in that order: ties still go to the lowest template.
    const auto v = static_cast<std::size_t>(turns.turns), step = turns.inner, period = v * step;
    const std::size_t n_rows = ranges.size() * v, n_blocks = (n_rows + row_block - 1) / row_block;
    const std::size_t cores = thread_count(threads);
    const std::size_t chunks = n_blocks == 0 ? 1 : std::max<std::size_t>(1, std::min(cores / n_blocks, n_ / 4096));
    std::vector<Best> chunk_best(chunks * n_rows);
    const simd::Isa isa = simd::isa();
    std::atomic<std::size_t> next{0};
    auto work = [&](std::size_t) {
        std::vector<float, CacheAligned<float>> q(row_block * stride_);
        std::vector<float> scores(row_block * template_block);
        for (std::size_t item; (item = next++) < n_blocks * chunks;) {
            const std::size_t block = item / chunks, chunk = item % chunks;
            const std::size_t r0 = block * row_block, r1 = std::min(n_rows, r0 + row_block), m = r1 - r0;
            std::fill(q.begin(), q.end(), 0.0f);
            // Row r: query r / v turned by s = r % v steps.
            for (std::size_t r = r0; r < r1; ++r) {
                const float* src = query(r / v);
                float* dst = q.data() + (r - r0) * stride_;
                const std::size_t s = r % v;
                for (std::size_t outer = 0; outer < dim_; outer += period)
                    for (std::size_t k = 0; k < v; ++k)
                        std::copy_n(src + outer + k * step, step, dst + outer + ((k + s) % v) * step);
            }
            std::size_t lo = n_, hi = 0;
            for (std::size_t r = r0; r < r1; ++r) {
                const Range& range = ranges[r / v];
                if (range.first < range.end) lo = std::min(lo, range.first), hi = std::max(hi, range.end);
            }
            if (lo >= hi) continue;
            const std::size_t span = (hi - lo + chunks - 1) / chunks;
            const std::size_t c0 = std::min(hi, lo + chunk * span), c1 = std::min(hi, c0 + span);
            const std::size_t groups = (m + query_tile - 1) / query_tile;
            for (std::size_t t0 = c0; t0 < c1; t0 += template_block) {
                const std::size_t t1 = std::min(c1, t0 + template_block);
                for (std::size_t g = 0; g < groups; ++g)
                    kernels::dots(q.data() + g * query_tile * stride_, std::min(query_tile, m - g * query_tile),
                                  rows_.data() + t0 * stride_, t1 - t0, stride_,
                                  scores.data() + g * query_tile * template_block, template_block, isa);
                for (std::size_t r = r0; r < r1; ++r) {
                    const Range& range = ranges[r / v];
                    const float* sc = scores.data() + (r - r0) * template_block;
                    Best& b = chunk_best[chunk * n_rows + r];
                    for (std::size_t j = std::max(t0, range.first), end = std::min(t1, range.end); j < end; ++j)
                        if (b.index < 0 || sc[j - t0] > b.similarity)
                            b = {static_cast<long>(j), sc[j - t0], static_cast<int>(r % v)};
                }
            }
        }
    };
    const std::size_t n_threads = std::max<std::size_t>(1, std::min(n_blocks * chunks, cores));
    run_workers(n_threads, work);

    // Per query: the best over its chunks (in template order) and turns.
    std::vector<Best> out(ranges.size());
    for (std::size_t i = 0; i < ranges.size(); ++i)
        for (std::size_t k = 0; k < v; ++k)
            for (std::size_t c = 0; c < chunks; ++c) {
                const Best& b = chunk_best[c * n_rows + i * v + k];
                Best& o = out[i];
                if (b.index < 0) continue;
                if (o.index < 0 || b.similarity > o.similarity || (b.similarity == o.similarity && b.index < o.index))
                    o = b;
            }
    return out;
}

}  // namespace bvc3d::analysis

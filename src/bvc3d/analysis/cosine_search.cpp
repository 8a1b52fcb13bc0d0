#include "bvc3d/analysis/cosine_search.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>
#include <thread>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/simd.hpp"

namespace bvc3d::analysis {

namespace {

// The kernel's vectors: 16 floats, which each instruction set lowers to its own registers (one
// AVX-512 register, two AVX ones, four SSE ones). Every clone adds the same lanes in the same order,
// so the dot products are the same bits on every CPU.
typedef float f16 __attribute__((vector_size(64)));
constexpr std::size_t lanes = 16;
constexpr std::size_t query_tile = 4, template_tile = 3;  // 12 accumulators: 12 of AVX-512's 32 registers
constexpr std::size_t row_block = 64;                     // query rows per task (a multiple of query_tile)
constexpr std::size_t template_block = 256;               // templates per pass (~1 MB of 960 floats: in L2)

inline float lane_sum(const f16& v) {
    float s = 0;
    for (std::size_t k = 0; k < lanes; ++k) s += v[k];
    return s;
}

// out[i·out_stride + j] = q_i · t_j for the 4 query rows at q and the n template rows at t (rows
// `stride` floats apart, a multiple of 16, zero-padded).
BVC3D_DISPATCH
void dots_4xn(const float* q, const float* t, std::size_t n, std::size_t stride, float* out, std::size_t out_stride) {
    std::size_t j = 0;
    for (; j + template_tile <= n; j += template_tile) {
        f16 acc[query_tile][template_tile] = {};
        const float* t0 = t + j * stride;
        for (std::size_t k = 0; k < stride; k += lanes) {
            f16 tv[template_tile], qv;
            for (std::size_t b = 0; b < template_tile; ++b) simd::load(tv[b], t0 + b * stride + k);
            for (std::size_t a = 0; a < query_tile; ++a) {
                simd::load(qv, q + a * stride + k);
                for (std::size_t b = 0; b < template_tile; ++b) acc[a][b] += qv * tv[b];
            }
        }
        for (std::size_t a = 0; a < query_tile; ++a)
            for (std::size_t b = 0; b < template_tile; ++b) out[a * out_stride + j + b] = lane_sum(acc[a][b]);
    }
    for (; j < n; ++j) {
        f16 acc[query_tile] = {};
        const float* tj = t + j * stride;
        for (std::size_t k = 0; k < stride; k += lanes) {
            f16 tv, qv;
            simd::load(tv, tj + k);
            for (std::size_t a = 0; a < query_tile; ++a) {
                simd::load(qv, q + a * stride + k);
                acc[a] += qv * tv;
            }
        }
        for (std::size_t a = 0; a < query_tile; ++a) out[a * out_stride + j] = lane_sum(acc[a]);
    }
}

std::size_t padded(std::size_t dim) { return (dim + lanes - 1) / lanes * lanes; }

}  // namespace

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
    if (turns.turns < 1 || turns.inner < 1 || dim_ % (static_cast<std::size_t>(turns.turns) * turns.inner) != 0)
        throw InputError("query turns of " + std::to_string(turns.turns) + " steps of " + std::to_string(turns.inner) +
                         " values do not divide vectors of " + std::to_string(dim_));
    for (const Range& r : ranges)
        if (r.first > r.end || r.end > n_) throw InputError("a query's range of templates lies outside the index");
    // The queries as unit rows, checked here (the workers must not throw).
    std::vector<float, CacheAligned<float>> unit(ranges.size() * stride_);
    unit_rows(queries, stride_, unit.data());

    const auto v = static_cast<std::size_t>(turns.turns), step = turns.inner, period = v * step;
    const std::size_t n_rows = ranges.size() * v, n_blocks = (n_rows + row_block - 1) / row_block;
    std::vector<Best> row_best(n_rows);
    std::atomic<std::size_t> next{0};
    auto work = [&] {
        std::vector<float, CacheAligned<float>> q(row_block * stride_);
        std::vector<float> scores(row_block * template_block);
        for (std::size_t block; (block = next++) < n_blocks;) {
            const std::size_t r0 = block * row_block, r1 = std::min(n_rows, r0 + row_block), m = r1 - r0;
            std::fill(q.begin(), q.end(), 0.0f);
            // Row r: query r / v turned by s = r % v steps.
            for (std::size_t r = r0; r < r1; ++r) {
                const float* src = unit.data() + (r / v) * stride_;
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
            const std::size_t groups = (m + query_tile - 1) / query_tile;
            for (std::size_t t0 = lo; t0 < hi; t0 += template_block) {
                const std::size_t t1 = std::min(hi, t0 + template_block);
                for (std::size_t g = 0; g < groups; ++g)
                    dots_4xn(q.data() + g * query_tile * stride_, rows_.data() + t0 * stride_, t1 - t0, stride_,
                             scores.data() + g * query_tile * template_block, template_block);
                for (std::size_t r = r0; r < r1; ++r) {
                    const Range& range = ranges[r / v];
                    const float* sc = scores.data() + (r - r0) * template_block;
                    Best& b = row_best[r];
                    for (std::size_t j = std::max(t0, range.first), end = std::min(t1, range.end); j < end; ++j)
                        if (b.index < 0 || sc[j - t0] > b.similarity)
                            b = {static_cast<long>(j), sc[j - t0], static_cast<int>(r % v)};
                }
            }
        }
    };
    const std::size_t cores =
        threads > 0 ? static_cast<std::size_t>(threads) : std::max<std::size_t>(1, std::thread::hardware_concurrency());
    const std::size_t n_threads = std::max<std::size_t>(1, std::min(n_blocks, cores));
    std::vector<std::thread> pool;
    for (std::size_t k = 1; k < n_threads; ++k) pool.emplace_back(work);
    work();
    for (auto& t : pool) t.join();

    std::vector<Best> out(ranges.size());
    for (std::size_t i = 0; i < ranges.size(); ++i)
        for (std::size_t k = 0; k < v; ++k) {
            const Best& b = row_best[i * v + k];
            Best& o = out[i];
            if (b.index < 0) continue;
            if (o.index < 0 || b.similarity > o.similarity || (b.similarity == o.similarity && b.index < o.index))
                o = b;
        }
    return out;
}

}  // namespace bvc3d::analysis

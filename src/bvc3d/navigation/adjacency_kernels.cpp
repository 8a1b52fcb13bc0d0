#include "bvc3d/navigation/adjacency_kernels.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "bvc3d/core/simd.hpp"

#if BVC3D_HAVE_DISPATCH
#include <immintrin.h>
#endif

namespace bvc3d::kernels {

namespace {

// Lanes 0–7 and 8–15 added lane by lane, then as the place cells' reduce8.
inline double reduce16(const double* lane) {
    double s[8];
    for (int l = 0; l < 8; ++l) s[l] = lane[l] + lane[l + 8];
    return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

// One row, lane by lane: what every instruction set computes.
inline double row_sum(const std::uint16_t* col, const float* w, std::uint32_t count, const double* x) {
    double lane[16] = {};
    for (std::uint32_t o = 0; o < count; ++o) lane[o % 16] += double(w[o]) * x[col[o]];
    return reduce16(lane);
}

// A binary16's value: exact (every half is a float), so any conversion gives these bits.
inline float half_value(std::uint16_t bits) { return static_cast<float>(Eigen::numext::bit_cast<Eigen::half>(bits)); }

constexpr int max_block = 64;  // rows of a tile: the vectorised form keeps their accumulators on the stack

// The packed products, one (row, direction) at a time: what every instruction set computes.
void half_rows_each(const HalfTiles& t, const float* x, const float* f, float* y) {
    const auto K = std::size_t(t.K);
    std::vector<float> acc(std::size_t(t.block) * 4 * K);  // row r of the block, accumulator q: acc[(4r + q)·K + k]
    std::size_t s = 0;
    for (int b0 = 0; b0 < t.rows; b0 += t.block) {
        const int rb = std::min(t.block, t.rows - b0);
        std::fill(acc.begin(), acc.end(), 0.0f);
        for (int p = 0; p < t.panels; ++p)
            for (int r = 0; r < rb; ++r, ++s)
                for (std::uint32_t e = t.start[s]; e < t.start[s + 1]; ++e) {
                    float* a = &acc[(4 * std::size_t(r) + (t.phase[s] + e - t.start[s]) % 4) * K];
                    const float* xr = x + std::size_t(t.col[e]) * K;
                    for (std::size_t k = 0; k < K; ++k) a[k] += half_value(t.h[std::size_t(e) * K + k]) * xr[k];
                }
        for (int r = 0; r < rb; ++r) {
            const float* a = &acc[4 * std::size_t(r) * K];
            for (std::size_t k = 0; k < K; ++k)
                y[std::size_t(b0 + r) * K + k] = f[k] * ((a[k] + a[K + k]) + (a[2 * K + k] + a[3 * K + k]));
        }
    }
}

void half_columns_each(const HalfTiles& t, const float* x, const float* f, float* y) {
    const auto K = std::size_t(t.K);
    std::fill(y, y + std::size_t(t.rows) * K, 0.0f);
    std::size_t s = 0;
    for (int b0 = 0; b0 < t.rows; b0 += t.block) {
        const int rb = std::min(t.block, t.rows - b0);
        for (int p = 0; p < t.panels; ++p)
            for (int r = 0; r < rb; ++r, ++s) {
                const float* xr = x + std::size_t(b0 + r) * K;
                if (std::all_of(xr, xr + K, [](float v) { return v == 0.0f; })) continue;
                for (std::uint32_t e = t.start[s]; e < t.start[s + 1]; ++e) {
                    float* yr = y + std::size_t(t.col[e]) * K;
                    for (std::size_t k = 0; k < K; ++k) yr[k] -= half_value(t.h[std::size_t(e) * K + k]) * xr[k];
                }
            }
    }
    for (std::size_t o = 0; o < std::size_t(t.rows) * K; ++o) y[o] = f[o % K] * y[o];
}

#if BVC3D_HAVE_DISPATCH
// Eight directions, one AVX2 register (x86-64-v3, F16C's exact conversion): the same additions as above.
BVC3D_TARGET_V3 inline __m256 half_weights(const std::uint16_t* h) {
    return _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(h)));
}
BVC3D_TARGET_V3 inline __m256 half_times(const std::uint16_t* h, const float* x) {
    return _mm256_mul_ps(half_weights(h), _mm256_loadu_ps(x));
}

// The weights are fetched this many entries (4 KB) ahead of their use: the distance measured fastest
// (docs/performance.md#navigation-issue-30). A prefetch never faults: past the end it fetches a line for nothing
// (the address is formed as an integer, not as a pointer past the array).
constexpr std::size_t prefetch_entries = 256;
inline void prefetch_weights(const std::uint16_t* h) {
    const auto ahead = reinterpret_cast<std::uintptr_t>(h) + sizeof(*h) * 8 * prefetch_entries;  // 8 weights an entry
    _mm_prefetch(reinterpret_cast<const char*>(ahead), _MM_HINT_T0);
}

// One segment of a row into its four accumulators, entry o of the segment into a[o mod 4].
BVC3D_TARGET_V3 inline void half_segment_v3(const HalfTiles& t, std::size_t s, const float* x, __m256 a[4]) {
    const std::uint16_t* col = t.col.data() + t.start[s];
    const std::uint16_t* h = t.h.data() + 8 * std::size_t(t.start[s]);
    std::uint32_t left = t.start[s + 1] - t.start[s];
    for (; left >= 4; left -= 4, col += 4, h += 32) {
        prefetch_weights(h);  // 4 entries of 8 weights: one 64-byte line
        for (std::uint32_t q = 0; q < 4; ++q)
            a[q] = _mm256_add_ps(a[q], half_times(h + 8 * q, x + 8 * std::size_t(col[q])));
    }
    for (std::uint32_t q = 0; q < left; ++q)
        a[q] = _mm256_add_ps(a[q], half_times(h + 8 * q, x + 8 * std::size_t(col[q])));
}

BVC3D_TARGET_V3 void half_rows_v3(const HalfTiles& t, const float* x, const float* f, float* y) {
    const __m256 fv = _mm256_loadu_ps(f);
    alignas(32) float acc[max_block][4][8];  // row r of the block, accumulator q (o mod 4)
    std::size_t s = 0;
    for (int b0 = 0; b0 < t.rows; b0 += t.block) {
        const int rb = std::min(t.block, t.rows - b0);
        std::fill(&acc[0][0][0], &acc[0][0][0] + 32 * rb, 0.0f);
        for (int p = 0; p < t.panels; ++p)
            for (int r = 0; r < rb; ++r, ++s) {
                if (t.start[s] == t.start[s + 1]) continue;
                const unsigned ph = t.phase[s];
                __m256 a[4];
                for (unsigned q = 0; q < 4; ++q) a[q] = _mm256_load_ps(acc[r][(ph + q) % 4]);
                half_segment_v3(t, s, x, a);
                for (unsigned q = 0; q < 4; ++q) _mm256_store_ps(acc[r][(ph + q) % 4], a[q]);
            }
        for (int r = 0; r < rb; ++r) {
            const __m256 sum = _mm256_add_ps(_mm256_add_ps(_mm256_load_ps(acc[r][0]), _mm256_load_ps(acc[r][1])),
                                             _mm256_add_ps(_mm256_load_ps(acc[r][2]), _mm256_load_ps(acc[r][3])));
            _mm256_storeu_ps(y + 8 * std::size_t(b0 + r), _mm256_mul_ps(fv, sum));
        }
    }
}

// Entries e … e + N − 1 of one segment into their sums, y[col] −= h·x: all N sums are loaded before any is stored.
// A segment's columns are distinct, so this is the same as one by one; taken eight at a time, the loads need not
// wait on the stores before them (docs/performance.md#navigation-issue-30).
template <int N>
BVC3D_TARGET_V3 inline void column_updates_v3(const HalfTiles& t, std::uint32_t e, __m256 xr, float* y) {
    float* yr[N];
    __m256 v[N];
    for (int q = 0; q < N; ++q) yr[q] = y + 8 * std::size_t(t.col[e + q]);
    for (int q = 0; q < N; ++q) v[q] = _mm256_loadu_ps(yr[q]);
    for (int q = 0; q < N; ++q)
        v[q] = _mm256_sub_ps(v[q], _mm256_mul_ps(half_weights(&t.h[8 * std::size_t(e + q)]), xr));
    for (int q = 0; q < N; ++q) _mm256_storeu_ps(yr[q], v[q]);
}

BVC3D_TARGET_V3 void half_columns_v3(const HalfTiles& t, const float* x, const float* f, float* y) {
    std::fill(y, y + 8 * std::size_t(t.rows), 0.0f);
    std::size_t s = 0;
    for (int b0 = 0; b0 < t.rows; b0 += t.block) {
        const int rb = std::min(t.block, t.rows - b0);
        for (int p = 0; p < t.panels; ++p)
            for (int r = 0; r < rb; ++r, ++s) {
                const __m256 xr = _mm256_loadu_ps(x + 8 * std::size_t(b0 + r));
                if (!_mm256_movemask_ps(_mm256_cmp_ps(xr, _mm256_setzero_ps(), _CMP_NEQ_UQ))) continue;
                std::uint32_t e = t.start[s];
                for (; e + 8 <= t.start[s + 1]; e += 8) column_updates_v3<8>(t, e, xr, y);
                for (; e < t.start[s + 1]; ++e) column_updates_v3<1>(t, e, xr, y);
            }
    }
    const __m256 fv = _mm256_loadu_ps(f);
    for (int i = 0; i < t.rows; ++i)
        _mm256_storeu_ps(y + 8 * std::size_t(i), _mm256_mul_ps(fv, _mm256_loadu_ps(y + 8 * std::size_t(i))));
}

// 16 entries at a time in four registers of 4 lanes (AVX2 gathers, in the masked form: the unmasked one warns inside
// GCC 12's header); the tail, entry by entry into its lane, is the lanes' last additions as above.
BVC3D_TARGET_V3 inline double row_sum_v3(const std::uint16_t* col, const float* w, std::uint32_t count,
                                         const double* x) {
    __m256d acc[4] = {_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd()};
    const __m256d all = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
    std::uint32_t o = 0;
    for (; o + 16 <= count; o += 16)
        for (int q = 0; q < 4; ++q) {
            const __m128i c = _mm_cvtepu16_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(col + o + 4 * q)));
            const __m256d wd = _mm256_cvtps_pd(_mm_loadu_ps(w + o + 4 * q));
            const __m256d xv = _mm256_mask_i32gather_pd(_mm256_setzero_pd(), x, c, all, 8);
            acc[q] = _mm256_add_pd(acc[q], _mm256_mul_pd(wd, xv));
        }
    double lane[16];
    for (int q = 0; q < 4; ++q) _mm256_storeu_pd(lane + 4 * q, acc[q]);
    for (; o < count; ++o) lane[o % 16] += double(w[o]) * x[col[o]];
    return reduce16(lane);
}

BVC3D_TARGET_V3 void row_sums16_v3(const std::uint32_t* start, const std::uint16_t* col, const float* w, int rows,
                                   const double* x, double scale, double* out) {
    for (int i = 0; i < rows; ++i)
        out[i] = scale * row_sum_v3(col + start[i], w + start[i], start[i + 1] - start[i], x);
}

// GCC 12 warns inside its own AVX-512 headers (their _mm512_undefined_* placeholders) where these inline.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
// 16 entries at a time: two gathers of 8 x values, two accumulators (lanes 0–7, 8–15). A masked-off lane adds
// +0, which leaves a running sum from +0 as it is (it is never −0 in round-to-nearest), so the tails change no bit.
BVC3D_TARGET_V4 inline double row_sum_v4(const std::uint16_t* col, const float* w, std::uint32_t count,
                                         const double* x) {
    __m512d lo = _mm512_setzero_pd(), hi = _mm512_setzero_pd();
    std::uint32_t o = 0;
    for (; o + 16 <= count; o += 16) {
        const __m512i c = _mm512_cvtepu16_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(col + o)));
        const __m512 wf = _mm512_loadu_ps(w + o);
        const __m512d x_lo = _mm512_i32gather_pd(_mm512_castsi512_si256(c), x, 8);
        const __m512d x_hi = _mm512_i32gather_pd(_mm512_extracti64x4_epi64(c, 1), x, 8);
        lo = _mm512_add_pd(lo, _mm512_mul_pd(_mm512_cvtps_pd(_mm512_castps512_ps256(wf)), x_lo));
        hi = _mm512_add_pd(hi, _mm512_mul_pd(_mm512_cvtps_pd(_mm512_extractf32x8_ps(wf, 1)), x_hi));
    }
    for (int half = 0; half < 2 && o < count; ++half, o += 8) {
        const std::uint32_t left = count - o;
        const __mmask8 m = static_cast<__mmask8>(left >= 8 ? 0xff : (1u << left) - 1);
        const __m256i c = _mm256_cvtepu16_epi32(_mm_maskz_loadu_epi16(m, col + o));
        const __m512d xv = _mm512_mask_i32gather_pd(_mm512_setzero_pd(), m, c, x, 8);
        const __m512d p = _mm512_mul_pd(_mm512_cvtps_pd(_mm256_maskz_loadu_ps(m, w + o)), xv);
        if (half == 0) lo = _mm512_add_pd(lo, p);
        else hi = _mm512_add_pd(hi, p);
    }
    double lane[16];
    _mm512_storeu_pd(lane, lo);
    _mm512_storeu_pd(lane + 8, hi);
    return reduce16(lane);
}

BVC3D_TARGET_V4 void row_sums16_v4(const std::uint32_t* start, const std::uint16_t* col, const float* w, int rows,
                                   const double* x, double scale, double* out) {
    for (int i = 0; i < rows; ++i)
        out[i] = scale * row_sum_v4(col + start[i], w + start[i], start[i + 1] - start[i], x);
}
#pragma GCC diagnostic pop
#endif

}  // namespace

void row_sums16(const std::uint32_t* start, const std::uint16_t* col, const float* w, int rows, const double* x,
                double scale, double* out) {
#if BVC3D_HAVE_DISPATCH
    if (simd::isa() == simd::Isa::v4) return row_sums16_v4(start, col, w, rows, x, scale, out);
    if (simd::isa() == simd::Isa::v3) return row_sums16_v3(start, col, w, rows, x, scale, out);
#endif
    for (int i = 0; i < rows; ++i) out[i] = scale * row_sum(col + start[i], w + start[i], start[i + 1] - start[i], x);
}

HalfTiles::HalfTiles(const std::uint32_t* row_start, const std::uint16_t* row_col, const std::uint16_t* row_h,
                     int rows_, int K_, int block_, int panel)
    : rows(rows_), K(K_), block(block_), panels(std::max(1, (rows_ + panel - 1) / std::max(panel, 1))) {
    if (rows < 0 || K < 1 || block < 1 || block > max_block || panel < 1)
        throw std::invalid_argument("HalfTiles: " + std::to_string(rows) + " rows, " + std::to_string(K) +
                                    " weights an entry, blocks of " + std::to_string(block) + " rows (1 to " +
                                    std::to_string(max_block) + "), panels of " + std::to_string(panel) + " cells");
    for (int i = 0; i < rows; ++i)
        for (std::uint32_t e = row_start[i]; e < row_start[i + 1]; ++e)
            if (row_col[e] >= rows || (e > row_start[i] && row_col[e] <= row_col[e - 1]))
                throw std::invalid_argument("HalfTiles: row " + std::to_string(i) + "'s column " +
                                            std::to_string(row_col[e]) + " not ascending below the " +
                                            std::to_string(rows) + " rows");
    const auto k = std::size_t(K);
    start.push_back(0);
    std::vector<std::uint32_t> next(static_cast<std::size_t>(block));  // each row's first entry not yet laid out
    for (int b0 = 0; b0 < rows; b0 += block) {
        const int rb = std::min(block, rows - b0);
        std::copy_n(row_start + b0, rb, next.begin());
        for (int p = 0; p < panels; ++p)
            for (int r = 0; r < rb; ++r) {
                const std::uint32_t end = row_start[b0 + r + 1];
                phase.push_back(std::uint8_t((next[std::size_t(r)] - row_start[b0 + r]) % 4));
                for (auto& e = next[std::size_t(r)]; e < end && row_col[e] < (p + 1) * panel; ++e) {
                    col.push_back(row_col[e]);
                    h.insert(h.end(), row_h + std::size_t(e) * k, row_h + (std::size_t(e) + 1) * k);
                }
                start.push_back(std::uint32_t(col.size()));
            }
    }
}

void half_rows(const HalfTiles& t, const float* x, const float* f, float* y) {
#if BVC3D_HAVE_DISPATCH
    if (t.K == 8 && simd::isa() != simd::Isa::baseline) return half_rows_v3(t, x, f, y);
#endif
    half_rows_each(t, x, f, y);
}

void half_columns(const HalfTiles& t, const float* x, const float* f, float* y) {
#if BVC3D_HAVE_DISPATCH
    if (t.K == 8 && simd::isa() != simd::Isa::baseline) return half_columns_v3(t, x, f, y);
#endif
    half_columns_each(t, x, f, y);
}

}  // namespace bvc3d::kernels

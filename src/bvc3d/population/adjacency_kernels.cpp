#include "bvc3d/population/adjacency_kernels.hpp"

#include <Eigen/Core>
#include <algorithm>

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

constexpr int max_directions = 64;  // AdjacencyParams::n_hd's limit

// The packed products, one (row, direction) at a time: what every instruction set computes.
void half_rows_each(const std::uint32_t* start, const std::uint16_t* col, const std::uint16_t* h, int rows, int K,
                    const float* x, const float* f, float* y) {
    float acc[4][max_directions];
    for (int i = 0; i < rows; ++i) {
        for (auto& a : acc) std::fill(a, a + K, 0.0f);
        for (std::uint32_t e = start[i]; e < start[i + 1]; ++e) {
            float* a = acc[(e - start[i]) % 4];
            const float* xr = x + std::size_t(col[e]) * std::size_t(K);
            for (int k = 0; k < K; ++k) a[k] += half_value(h[std::size_t(e) * std::size_t(K) + std::size_t(k)]) * xr[k];
        }
        for (int k = 0; k < K; ++k)
            y[std::size_t(i) * std::size_t(K) + std::size_t(k)] =
                f[k] * ((acc[0][k] + acc[1][k]) + (acc[2][k] + acc[3][k]));
    }
}

void half_columns_each(const std::uint32_t* start, const std::uint16_t* col, const std::uint16_t* h, int rows, int K,
                       const float* x, const float* f, float* y) {
    std::fill(y, y + std::size_t(rows) * std::size_t(K), 0.0f);
    for (int j = 0; j < rows; ++j) {
        const float* xr = x + std::size_t(j) * std::size_t(K);
        if (std::all_of(xr, xr + K, [](float v) { return v == 0.0f; })) continue;
        for (std::uint32_t e = start[j]; e < start[j + 1]; ++e) {
            float* yr = y + std::size_t(col[e]) * std::size_t(K);
            for (int k = 0; k < K; ++k)
                yr[k] -= half_value(h[std::size_t(e) * std::size_t(K) + std::size_t(k)]) * xr[k];
        }
    }
    for (std::size_t o = 0; o < std::size_t(rows) * std::size_t(K); ++o) y[o] = f[o % std::size_t(K)] * y[o];
}

#if BVC3D_HAVE_DISPATCH
// Eight directions, one AVX2 register (x86-64-v3, F16C's exact conversion): the same additions as above.
BVC3D_TARGET_V3 inline __m256 half_times(const std::uint16_t* h, const float* x) {
    return _mm256_mul_ps(_mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(h))), _mm256_loadu_ps(x));
}

BVC3D_TARGET_V3 void half_rows_v3(const std::uint32_t* start, const std::uint16_t* col, const std::uint16_t* h,
                                  int rows, const float* x, const float* f, float* y) {
    const __m256 fv = _mm256_loadu_ps(f);
    for (int i = 0; i < rows; ++i) {
        __m256 a0 = _mm256_setzero_ps(), a1 = a0, a2 = a0, a3 = a0;
        std::uint32_t e = start[i];
        const std::uint32_t end = start[i + 1];
        for (; e + 4 <= end; e += 4) {
            a0 = _mm256_add_ps(a0, half_times(h + 8 * std::size_t(e), x + 8 * std::size_t(col[e])));
            a1 = _mm256_add_ps(a1, half_times(h + 8 * std::size_t(e + 1), x + 8 * std::size_t(col[e + 1])));
            a2 = _mm256_add_ps(a2, half_times(h + 8 * std::size_t(e + 2), x + 8 * std::size_t(col[e + 2])));
            a3 = _mm256_add_ps(a3, half_times(h + 8 * std::size_t(e + 3), x + 8 * std::size_t(col[e + 3])));
        }
        if (e < end) a0 = _mm256_add_ps(a0, half_times(h + 8 * std::size_t(e), x + 8 * std::size_t(col[e])));
        if (e + 1 < end)
            a1 = _mm256_add_ps(a1, half_times(h + 8 * std::size_t(e + 1), x + 8 * std::size_t(col[e + 1])));
        if (e + 2 < end)
            a2 = _mm256_add_ps(a2, half_times(h + 8 * std::size_t(e + 2), x + 8 * std::size_t(col[e + 2])));
        _mm256_storeu_ps(y + 8 * std::size_t(i),
                         _mm256_mul_ps(fv, _mm256_add_ps(_mm256_add_ps(a0, a1), _mm256_add_ps(a2, a3))));
    }
}

BVC3D_TARGET_V3 void half_columns_v3(const std::uint32_t* start, const std::uint16_t* col, const std::uint16_t* h,
                                     int rows, const float* x, const float* f, float* y) {
    std::fill(y, y + 8 * std::size_t(rows), 0.0f);
    for (int j = 0; j < rows; ++j) {
        const __m256 xr = _mm256_loadu_ps(x + 8 * std::size_t(j));
        if (!_mm256_movemask_ps(_mm256_cmp_ps(xr, _mm256_setzero_ps(), _CMP_NEQ_UQ))) continue;
        for (std::uint32_t e = start[j]; e < start[j + 1]; ++e) {
            float* yr = y + 8 * std::size_t(col[e]);
            const __m256 p = _mm256_mul_ps(
                _mm256_cvtph_ps(_mm_loadu_si128(reinterpret_cast<const __m128i*>(h + 8 * std::size_t(e)))), xr);
            _mm256_storeu_ps(yr, _mm256_sub_ps(_mm256_loadu_ps(yr), p));
        }
    }
    const __m256 fv = _mm256_loadu_ps(f);
    for (int i = 0; i < rows; ++i)
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

void half_rows(const std::uint32_t* start, const std::uint16_t* col, const std::uint16_t* h, int rows, int K,
               const float* x, const float* f, float* y) {
#if BVC3D_HAVE_DISPATCH
    if (K == 8 && simd::isa() != simd::Isa::baseline) return half_rows_v3(start, col, h, rows, x, f, y);
#endif
    half_rows_each(start, col, h, rows, K, x, f, y);
}

void half_columns(const std::uint32_t* start, const std::uint16_t* col, const std::uint16_t* h, int rows, int K,
                  const float* x, const float* f, float* y) {
#if BVC3D_HAVE_DISPATCH
    if (K == 8 && simd::isa() != simd::Isa::baseline) return half_columns_v3(start, col, h, rows, x, f, y);
#endif
    half_columns_each(start, col, h, rows, K, x, f, y);
}

}  // namespace bvc3d::kernels

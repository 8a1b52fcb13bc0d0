#include "bvc3d/population/adjacency_kernels.hpp"

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

#if BVC3D_HAVE_DISPATCH
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
#endif
    for (int i = 0; i < rows; ++i) out[i] = scale * row_sum(col + start[i], w + start[i], start[i + 1] - start[i], x);
}

}  // namespace bvc3d::kernels

#include "bvc3d/core/vector_exp.hpp"

#include <sleef.h>

#include <cstring>

#include "bvc3d/core/simd.hpp"

#if BVC3D_HAVE_DISPATCH
#include <immintrin.h>
// sleef.h declares its AVX and AVX-512 functions only where the whole translation unit is compiled for
// them; here only the functions below are, so their two are declared for those targets.
#pragma GCC push_options
#pragma GCC target("avx512f")
extern "C" __m512d Sleef_cinz_expd8_u10avx512fnofma(__m512d);
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx")
extern "C" __m256d Sleef_cinz_expd4_u10avx(__m256d);
#pragma GCC pop_options
#endif

namespace bvc3d {

namespace {

// The last n % width arguments, padded with zeros to a whole vector (exp(0) is harmless). One loop per
// instruction set: SLEEF's functions take that set's own vector type.
struct Tail {
    double x[8] = {}, y[8] = {};
};

#if BVC3D_HAVE_DISPATCH
BVC3D_TARGET_V4 void exp_v4(const double* x, double* y, std::size_t n) {
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) _mm512_storeu_pd(y + i, Sleef_cinz_expd8_u10avx512fnofma(_mm512_loadu_pd(x + i)));
    if (i == n) return;
    Tail t;
    std::memcpy(t.x, x + i, (n - i) * sizeof(double));
    _mm512_storeu_pd(t.y, Sleef_cinz_expd8_u10avx512fnofma(_mm512_loadu_pd(t.x)));
    std::memcpy(y + i, t.y, (n - i) * sizeof(double));
}

BVC3D_TARGET_V3 void exp_v3(const double* x, double* y, std::size_t n) {
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) _mm256_storeu_pd(y + i, Sleef_cinz_expd4_u10avx(_mm256_loadu_pd(x + i)));
    if (i == n) return;
    Tail t;
    std::memcpy(t.x, x + i, (n - i) * sizeof(double));
    _mm256_storeu_pd(t.y, Sleef_cinz_expd4_u10avx(_mm256_loadu_pd(t.x)));
    std::memcpy(y + i, t.y, (n - i) * sizeof(double));
}
#endif

void exp_baseline(const double* x, double* y, std::size_t n) {
#if defined(__SSE2__)
    std::size_t i = 0;
    for (; i + 2 <= n; i += 2) _mm_storeu_pd(y + i, Sleef_cinz_expd2_u10sse2(_mm_loadu_pd(x + i)));
    if (i < n) y[i] = Sleef_cinz_expd1_u10purec(x[i]);
#else
    for (std::size_t i = 0; i < n; ++i) y[i] = Sleef_cinz_expd1_u10purec(x[i]);
#endif
}

}  // namespace

void vector_exp(const double* x, double* y, std::size_t n) {
#if BVC3D_HAVE_DISPATCH
    switch (simd::isa()) {
        case simd::Isa::v4:
            return exp_v4(x, y, n);
        case simd::Isa::v3:
            return exp_v3(x, y, n);
        case simd::Isa::baseline:
            break;
    }
#endif
    exp_baseline(x, y, n);
}

}  // namespace bvc3d

#include "bvc3d/core/vector_math.hpp"

#include <sleef.h>

#include <cstring>

#include "bvc3d/core/simd.hpp"

#if BVC3D_HAVE_DISPATCH
#include <immintrin.h>
// sleef.h declares its AVX and AVX-512 functions only where the whole translation unit is compiled for
// them; here only the functions below are, so theirs are declared for those targets.
#pragma GCC push_options
#pragma GCC target("avx512f")
extern "C" __m512d Sleef_cinz_expd8_u10avx512fnofma(__m512d);
extern "C" __m512d Sleef_cinz_tanhd8_u35avx512fnofma(__m512d);
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx")
extern "C" __m256d Sleef_cinz_expd4_u10avx(__m256d);
extern "C" __m256d Sleef_cinz_tanhd4_u35avx(__m256d);
#pragma GCC pop_options
#endif

namespace bvc3d {

namespace {

// The last n % width arguments, padded with zeros to a whole vector (exp(0) and tanh(0) are harmless). One loop
// per instruction set: SLEEF's functions take that set's own vector type.
struct Tail {
    double x[8] = {}, y[8] = {};
};

// SLEEF's function `name` of accuracy `u` (u10: 1.0 ulp, u35: 3.5 ulp) in each instruction set's form, as static
// members (a template takes these; their declarations' attributes keep the functions themselves from being template
// arguments).
#if BVC3D_HAVE_DISPATCH
#define BVC3D_SLEEF_WIDE(name, u)                                                                       \
    BVC3D_TARGET_V4 static __m512d v4(__m512d x) { return Sleef_cinz_##name##d8_##u##avx512fnofma(x); } \
    BVC3D_TARGET_V3 static __m256d v3(__m256d x) { return Sleef_cinz_##name##d4_##u##avx(x); }
#else
#define BVC3D_SLEEF_WIDE(name, u)
#endif
#if defined(__SSE2__)
#define BVC3D_SLEEF_SSE2(name, u) \
    static __m128d sse2(__m128d x) { return Sleef_cinz_##name##d2_##u##sse2(x); }
#else
#define BVC3D_SLEEF_SSE2(name, u)
#endif
#define BVC3D_SLEEF(type, name, u)                                                     \
    struct type {                                                                      \
        BVC3D_SLEEF_WIDE(name, u)                                                      \
        BVC3D_SLEEF_SSE2(name, u)                                                      \
        static double scalar(double x) { return Sleef_cinz_##name##d1_##u##purec(x); } \
    };
BVC3D_SLEEF(Exp, exp, u10)
BVC3D_SLEEF(Tanh, tanh, u35)  // 3.5 ulp: a sixth of u10's time here, and far below what a rollout's return resolves

#if BVC3D_HAVE_DISPATCH
template <class F>
BVC3D_TARGET_V4 void map_v4(const double* x, double* y, std::size_t n) {
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) _mm512_storeu_pd(y + i, F::v4(_mm512_loadu_pd(x + i)));
    if (i == n) return;
    Tail t;
    std::memcpy(t.x, x + i, (n - i) * sizeof(double));
    _mm512_storeu_pd(t.y, F::v4(_mm512_loadu_pd(t.x)));
    std::memcpy(y + i, t.y, (n - i) * sizeof(double));
}

template <class F>
BVC3D_TARGET_V3 void map_v3(const double* x, double* y, std::size_t n) {
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) _mm256_storeu_pd(y + i, F::v3(_mm256_loadu_pd(x + i)));
    if (i == n) return;
    Tail t;
    std::memcpy(t.x, x + i, (n - i) * sizeof(double));
    _mm256_storeu_pd(t.y, F::v3(_mm256_loadu_pd(t.x)));
    std::memcpy(y + i, t.y, (n - i) * sizeof(double));
}
#endif

template <class F>
void map_baseline(const double* x, double* y, std::size_t n) {
    std::size_t i = 0;
#if defined(__SSE2__)
    for (; i + 2 <= n; i += 2) _mm_storeu_pd(y + i, F::sse2(_mm_loadu_pd(x + i)));
#endif
    for (; i < n; ++i) y[i] = F::scalar(x[i]);
}

template <class F>
void map(const double* x, double* y, std::size_t n) {
#if BVC3D_HAVE_DISPATCH
    switch (simd::isa()) {
        case simd::Isa::v4:
            return map_v4<F>(x, y, n);
        case simd::Isa::v3:
            return map_v3<F>(x, y, n);
        case simd::Isa::baseline:
            break;
    }
#endif
    map_baseline<F>(x, y, n);
}

}  // namespace

void vector_exp(const double* x, double* y, std::size_t n) { map<Exp>(x, y, n); }

void vector_tanh(const double* x, double* y, std::size_t n) { map<Tanh>(x, y, n); }

}  // namespace bvc3d

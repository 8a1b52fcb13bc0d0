#include "bvc3d/place/place_kernels.hpp"

#include "bvc3d/core/simd.hpp"

namespace bvc3d::kernels {

using simd::f8;

namespace {
template <class V>
inline float reduce8(const V& acc, int f) {
    return ((acc[f] + acc[f + 1]) + (acc[f + 2] + acc[f + 3])) + ((acc[f + 4] + acc[f + 5]) + (acc[f + 6] + acc[f + 7]));
}

template <int N>
struct floats {
    typedef float type __attribute__((vector_size(4 * N)));
};

// P pairs (2P rows) at once, with vectors of N floats (16: a pair's block in one AVX-512 register;
// 8: one row's block). The 2P rows' accumulator chains share each load of v: the loop runs at the
// machine's multiply and add throughput, not at an add's latency. Every lane does what a one-row
// loop of 8 lanes does, whatever N and P: the bits do not change. P·16/N = 8 chains: two FP ports ×
// an add's 3–4 cycles of latency need 6–8 in flight; 16 spill registers.
template <int N, int P>
[[gnu::always_inline]] inline void pairs_times(const float* W, std::size_t pair_stride, const float* v2, std::size_t n,
                                               float* out) {
    using V = typename floats<N>::type;
    constexpr int H = 16 / N;  // vectors per pair block
    V acc[P][H];
    for (int p = 0; p < P; ++p)
        for (int h = 0; h < H; ++h) acc[p][h] = V{};
    for (std::size_t j = 0; j < 2 * n; j += 16) {
        V b[H];
        for (int h = 0; h < H; ++h) simd::load(b[h], v2 + j + h * N);
        for (int p = 0; p < P; ++p)
            for (int h = 0; h < H; ++h) {
                V a;
                simd::load(a, W + p * pair_stride + j + h * N);
                acc[p][h] += a * b[h];
            }
    }
    for (int p = 0; p < P; ++p) {
        if constexpr (N == 16) {
            out[2 * p] = reduce8(acc[p][0], 0);
            out[2 * p + 1] = reduce8(acc[p][0], 8);
        } else {
            out[2 * p] = reduce8(acc[p][0], 0);
            out[2 * p + 1] = reduce8(acc[p][1], 0);
        }
    }
}

template <int N>
[[gnu::always_inline]] inline void paired(const float* W, std::size_t pair_stride, const float* v2, std::size_t n,
                                          int pairs, float* out) {
    constexpr int P = N == 16 ? 8 : 4;
    int p = 0;
    for (; p + P <= pairs; p += P) pairs_times<N, P>(W + p * pair_stride, pair_stride, v2, n, out + 2 * p);
    for (; p < pairs; ++p) pairs_times<N, 1>(W + p * pair_stride, pair_stride, v2, n, out + 2 * p);
}

#if BVC3D_HAVE_DISPATCH
BVC3D_TARGET_V4 void paired_v4(const float* W, std::size_t pair_stride, const float* v2, std::size_t n, int pairs,
                               float* out) {
    paired<16>(W, pair_stride, v2, n, pairs, out);
}
BVC3D_TARGET_V3 void paired_v3(const float* W, std::size_t pair_stride, const float* v2, std::size_t n, int pairs,
                               float* out) {
    paired<8>(W, pair_stride, v2, n, pairs, out);
}
#endif
}  // namespace

void paired_matvec(const float* W, std::size_t pair_stride, const float* v2, std::size_t n, int pairs, float* out) {
#if BVC3D_HAVE_DISPATCH
    switch (simd::isa()) {
        case simd::Isa::v4: return paired_v4(W, pair_stride, v2, n, pairs, out);
        case simd::Isa::v3: return paired_v3(W, pair_stride, v2, n, pairs, out);
        case simd::Isa::baseline: break;
    }
#endif
    paired<8>(W, pair_stride, v2, n, pairs, out);
}

BVC3D_DISPATCH
float sum8(const float* v, std::size_t n) {
    f8 acc = {0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t j = 0; j < n; j += 8) {
        f8 a;
        simd::load(a, v + j);
        acc += a;
    }
    return reduce8(acc, 0);
}

BVC3D_DISPATCH
void oja_row(float* __restrict w, const float* __restrict v, float a, float c, float tiny, std::size_t n) {
    const f8 lo = {tiny, tiny, tiny, tiny, tiny, tiny, tiny, tiny}, zero = {0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t j = 0; j < n; j += 8) {
        f8 x, b;
        simd::load(x, w + 2 * j);
        simd::load(b, v + j);
        x = x + a * (b - c * x);
        simd::store(w + 2 * j, (x < lo) & (x > -lo) ? zero : x);  // NaN stays NaN
    }
}

}  // namespace bvc3d::kernels

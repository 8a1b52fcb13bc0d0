#include "bvc3d/place/place_kernels.hpp"

#include "bvc3d/core/simd.hpp"

namespace bvc3d::kernels {

using simd::f8;

namespace {
inline float reduce8(const f8& acc) {
    return ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
}

// Rows i .. i+R-1 at once: R independent accumulator chains share each load of v, so the loop runs
// at the machine's load and multiply-add throughput instead of one add's latency per 8 columns.
// Each row's sum is the same sequence of operations as a one-row loop: the bits do not change.
// Eight rows: two FP ports × an add's 3–4 cycles of latency need 6–8 chains in flight (4 left the
// ports idle half the time: 0.8× the time at 8 on AVX2 and AVX-512; 16 spills registers).
template <int R>
inline void rows_times(const float* W, std::size_t stride, const float* v, std::size_t n, float* out) {
    f8 acc[R];
    for (int r = 0; r < R; ++r) acc[r] = f8{0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t j = 0; j < n; j += 8) {
        f8 b;
        simd::load(b, v + j);
        for (int r = 0; r < R; ++r) {
            f8 a;
            simd::load(a, W + r * stride + j);
            acc[r] += a * b;
        }
    }
    for (int r = 0; r < R; ++r) out[r] = reduce8(acc[r]);
}
}  // namespace

BVC3D_DISPATCH
void matvec8(const float* W, std::size_t stride, const float* v, std::size_t n, int rows, float* out) {
    int i = 0;
    for (; i + 8 <= rows; i += 8) rows_times<8>(W + static_cast<std::size_t>(i) * stride, stride, v, n, out + i);
    for (; i + 4 <= rows; i += 4) rows_times<4>(W + static_cast<std::size_t>(i) * stride, stride, v, n, out + i);
    for (; i < rows; ++i) rows_times<1>(W + static_cast<std::size_t>(i) * stride, stride, v, n, out + i);
}

BVC3D_DISPATCH
float sum8(const float* v, std::size_t n) {
    f8 acc = {0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t j = 0; j < n; j += 8) {
        f8 a;
        simd::load(a, v + j);
        acc += a;
    }
    return reduce8(acc);
}

BVC3D_DISPATCH
void oja_row(float* __restrict w, const float* __restrict v, float a, float c, float tiny, std::size_t n) {
    const f8 lo = {tiny, tiny, tiny, tiny, tiny, tiny, tiny, tiny}, zero = {0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t j = 0; j < n; j += 8) {
        f8 x, b;
        simd::load(x, w + j);
        simd::load(b, v + j);
        x = x + a * (b - c * x);
        simd::store(w + j, (x < lo) & (x > -lo) ? zero : x);  // NaN stays NaN
    }
}

}  // namespace bvc3d::kernels

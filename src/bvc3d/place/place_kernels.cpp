#include "bvc3d/place/place_kernels.hpp"

#include "bvc3d/core/simd.hpp"

namespace bvc3d::kernels {

using simd::f8;

namespace {
inline float reduce8(const f8& acc) {
    return ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]));
}
}  // namespace

BVC3D_DISPATCH
void matvec8(const float* W, std::size_t stride, const float* v, std::size_t n, int rows, float* out) {
    for (int i = 0; i < rows; ++i) {
        const float* w = W + static_cast<std::size_t>(i) * stride;
        f8 acc = {0, 0, 0, 0, 0, 0, 0, 0};
        for (std::size_t j = 0; j < n; j += 8) {
            f8 a, b;
            simd::load(a, w + j);
            simd::load(b, v + j);
            acc += a * b;
        }
        out[i] = reduce8(acc);
    }
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
void oja_row(float* __restrict w, const float* __restrict v, float a, float c, std::size_t n) {
    for (std::size_t j = 0; j < n; ++j) w[j] = w[j] + a * (v[j] - c * w[j]);
}

}  // namespace bvc3d::kernels

#pragma once
// The inner loops of the place-cell network, vectorised (see core/simd.hpp). Sums use 8 running
// lanes and a fixed reduction tree, so every instruction set gives the same bits.
#include <cstddef>

namespace bvc3d::kernels {

// out[i] = Σ_j W[i·stride + j]·v[j] for i < rows; n and stride are multiples of 8.
void matvec8(const float* W, std::size_t stride, const float* v, std::size_t n, int rows, float* out);
// Σ_j v[j], n a multiple of 8.
float sum8(const float* v, std::size_t n);
// Oja's update of one row: w[j] += a·(v[j] - c·w[j]), a result smaller than `tiny` in magnitude
// stored as 0; n a multiple of 8.
void oja_row(float* w, const float* v, float a, float c, float tiny, std::size_t n);

}  // namespace bvc3d::kernels

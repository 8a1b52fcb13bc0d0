#pragma once
// The inner loops of the place-cell network, vectorised (see core/simd.hpp). Sums use 8 running
// lanes and a fixed reduction tree, so every instruction set gives the same bits.
//
// Paired layout: the weights of rows 2p and 2p+1 are interleaved by blocks of 8 columns, so that
// one 16-float (AVX-512) register holds the same 8 columns of two rows and each row still has its
// own 8 lanes. Pair p starts at W + p·pair_stride; columns 8b..8b+7 of row 2p+h are at 16b + 8h.
#include <cstddef>

namespace bvc3d::kernels {

// Where column j of a row sits, counted from the row's first block (row 2p+h: W + p·pair_stride + 8h).
inline std::size_t paired_column(std::size_t j) { return (j / 8) * 16 + j % 8; }

// out[2p + h] = Σ_j W_(2p+h)[j]·v[j] for p < pairs, h = 0, 1; `v2` is v in the paired layout of one
// pair (each block of 8 twice: v2[16b + 8h + k] = v[8b + k]); n is a multiple of 8.
void paired_matvec(const float* W, std::size_t pair_stride, const float* v2, std::size_t n, int pairs, float* out);
// Σ_j v[j], n a multiple of 8.
float sum8(const float* v, std::size_t n);
// Oja's update of one row in the paired layout (w: its first block; its blocks are 16 floats apart):
// w[j] += a·(v[j] - c·w[j]), a result smaller than `tiny` in magnitude stored as 0; n a multiple of 8.
void oja_row(float* w, const float* v, float a, float c, float tiny, std::size_t n);

}  // namespace bvc3d::kernels

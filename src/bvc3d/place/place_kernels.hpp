#pragma once
// The inner loops of the place-cell network, vectorised (see core/simd.hpp). Sums use 8 running
// lanes and a fixed reduction tree, so every instruction set gives the same bits.
//
// Paired layout: the weights of rows 2p and 2p+1 are interleaved by blocks of 8 columns, so that
// one 16-float (AVX-512) register holds the same 8 columns of two rows and each row still has its
// own 8 lanes. Pair p starts at W + p·pair_stride; columns 8b..8b+7 of row 2p+h are at 16b + 8h.
#include <cstddef>
#include <cstdint>

namespace bvc3d::kernels {

// Where column j of a row sits, counted from the row's first block (row 2p+h: W + p·pair_stride + 8h).
inline std::size_t paired_column(std::size_t j) { return (j / 8) * 16 + j % 8; }

// For each step t < steps: out[t·out_stride + i] = Σ_j W_i[j]·v_t[j] for every row i < 2·pairs, with
// v_t = v + t·v_stride (plain layout, n entries, n a multiple of 8). Each row's sum is the same
// sequence of operations whatever `steps` (8 lanes, then reduce8): one pass over the weights serves up
// to 8 steps (one load of a weight block feeds 8 products) and gives the bits a pass per step gives.
// Blocks of 8 columns where the steps' inputs are all 0 are skipped (BVC rates far from every return
// are exact zeros): with finite weights this leaves every sum's bits as they are (see nonzero_blocks).
void paired_products(const float* W, std::size_t pair_stride, const float* v, std::size_t v_stride, std::size_t n,
                     int pairs, int steps, float* out, std::size_t out_stride);
// A binary mask M (rows × n, entries 0 or 1) times v, for one step, by columns: column j's bits are
// bits[j·col_words ...], bit k of word r the entry of row 16r + k (col_words·16 ≥ rows). Only the columns
// where v[j] is not 0 are read, each adding v[j] to the rows whose bit is set, in lane j mod 8 of each row;
// out[i] for i < rows is reduce8 of row i's lanes: the bits paired_products gives for M as floats (1·x = x,
// and a skipped 0·x = +0 changes no sum). `lanes`: room for 8·16·col_words floats. v finite, n any.
void mask_products(const std::uint16_t* bits, std::size_t col_words, const float* v, std::size_t n, std::size_t rows,
                   float* lanes, float* out);
// Row `w` (its first block; blocks 16 floats apart) times v: the bits of paired_products for that row.
float paired_row_product(const float* w, const float* v, std::size_t n);
// out[j] = (float)in[j] for j < n, a result smaller than `tiny` in magnitude stored as 0; returns the
// index of the first non-finite in[j] (then out is unspecified), or n.
std::size_t to_floats(const double* in, float* out, std::size_t n, float tiny);
// Σ_j v[j], n a multiple of 8.
float sum8(const float* v, std::size_t n);
// The membrane's leaky step for n cells: s[i] += k·(−s[i] + drive[i] − inhibition), then
// v[i] = gain·max(s[i], 0) (the caller takes tanh of the cells with s[i] > 0). Lists those cells'
// indices in `positive` (room for n), in order, and returns how many; *finite is false when some s[i]
// is not finite. Each cell's operations are the scalar ones, in the same order.
std::size_t membrane_step(float* s, const float* drive, std::size_t n, float k, float inhibition, float gain, float* v,
                          int* positive, bool* finite);
// Oja's update of one row in the paired layout (w: its first block; its blocks are 16 floats apart):
// w[j] += a·(v[j] - c·w[j]), a result smaller than `tiny` in magnitude stored as 0; n a multiple of 8.
// Returns whether every result is finite (the products' skipping of zero inputs relies on finite weights).
bool oja_row(float* w, const float* v, float a, float c, float tiny, std::size_t n);

}  // namespace bvc3d::kernels

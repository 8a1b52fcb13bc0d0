#pragma once
// The inner loop of a pruned adjacency's products (hd_adjacency.hpp), vectorised (see core/simd.hpp).
// Takes: a matrix in compressed rows (uint16 column indices, float32 weights) and a dense vector x. Gives: each
// row's sum Σ_e w_e·x[col_e] in 16 lanes — entry o of a row (counted from the row's first) goes to lane o mod 16,
// each lane sums in order, and the lanes are added in a fixed tree — so every instruction set gives the same bits.
#include <cstdint>

namespace bvc3d::kernels {

// out[i] = scale · Σ_{e ∈ [start[i], start[i+1])} double(w[e])·x[col[e]] for i < rows, in 16 lanes as above.
void row_sums16(const std::uint32_t* start, const std::uint16_t* col, const float* w, int rows, const double* x,
                double scale, double* out);

}  // namespace bvc3d::kernels

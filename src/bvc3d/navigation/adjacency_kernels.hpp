#pragma once
// Navigation stage: the inner loops of the adjacency's frozen copies (sparse_adjacency.hpp, packed_adjacency.hpp),
// vectorised (see core/simd.hpp). Each fixes an order of its additions that every instruction set keeps, so every one
// gives the same bits.
//
// row_sums16: a matrix in compressed rows (uint16 column indices, float32 weights), a dense vector x: each row's sum
// Σ_e w_e·x[col_e] in 16 lanes — entry o of a row (counted from the row's first) goes to lane o mod 16, each lane sums
// in order, and the lanes are added in a fixed tree.
//
// half_rows / half_columns: the n_hd matrices of a PackedAdjacency on one pattern, each entry holding n_hd weights
// as IEEE binary16 bits (h[e·K + k], K = n_hd), and a state X of n × K floats (X[j·K + k]: cell j along direction k).
// Every sum is float32, one per (row, direction):
//   half_rows:     Y[i·K + k] = f_k · ((a0 + a1) + (a2 + a3)),  a_q = Σ_{o ≡ q mod 4} h_{e,k}·X[col_e·K + k]
//                  over the entries e of row i in column order (o counted from the row's first)
//   half_columns:  Y[i·K + k] = f_k · (0 − Σ_{j, e ∈ row j, col_e = i} h_{e,k}·X[j·K + k]),  j ascending, rows with
//                  a non-zero X[j·K + ·] only: Wᵀ·X, which is −W·X for an antisymmetric W
// They read the entries in tiles (HalfTiles), for the caches: the rows in blocks, the columns in panels, a block's
// rows taken panel by panel, so that the states a block reads (rows) or the sums it adds into (columns) stay within
// one panel's cells while its entries stream past. Row i's entries in panel p go on from where panel p − 1 left them,
// in the same accumulators, and the columns form still meets the rows j in ascending order: the sums above, bit for
// bit, whatever the tiles' sizes.
#include <cstdint>
#include <vector>

namespace bvc3d::kernels {

// out[i] = scale · Σ_{e ∈ [start[i], start[i+1])} double(w[e])·x[col[e]] for i < rows, in 16 lanes as above.
void row_sums16(const std::uint32_t* start, const std::uint16_t* col, const float* w, int rows, const double* x,
                double scale, double* out);

// A pattern in compressed rows (start: rows + 1 offsets; col ascending within a row; h: K per entry) laid out in
// tiles: segment (b, p, r) holds the entries of row b·block + r with columns in [p·panel, (p + 1)·panel), and the
// segments are stored in the order b, p, r (the last block may be shorter).
struct HalfTiles {
    HalfTiles(const std::uint32_t* start, const std::uint16_t* col, const std::uint16_t* h, int rows, int K,
              int block = 64, int panel = 512);
    int rows, K, block, panels;
    std::vector<std::uint32_t> start;   // segment s: entries [start[s], start[s + 1])
    std::vector<std::uint8_t> phase;    // segment s: its row's entries in earlier panels, mod 4
    std::vector<std::uint16_t> col, h;  // h: K binary16 weights an entry
};

// The packed products above (K = 8 vectorised, any other K in the same order one by one).
void half_rows(const HalfTiles& t, const float* x, const float* f, float* y);
void half_columns(const HalfTiles& t, const float* x, const float* f, float* y);

}  // namespace bvc3d::kernels

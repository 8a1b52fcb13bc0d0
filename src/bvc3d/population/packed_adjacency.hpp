#pragma once
// Population stage: a frozen copy of an HD-conditioned adjacency (hd_adjacency.hpp) made for the rollouts of
// navigation (reward_cells.hpp), where one decision multiplies every direction's matrix by its own state a few
// times. Takes: a learned HdAdjacency and `prune`. Gives: the products of all directions at once,
//   Y[i][k] = (W_rec[k]·X[·][k])_i      X, Y: n × n_hd float32, row i holding cell i along every direction k,
// with W_rec[k] the matrix SparseAdjacency keeps (|w| > prune·max|W_rec[k]|, others 0) and each kept weight rounded
// to the nearest 16-bit float (IEEE binary16) after dividing by max|W_rec[k]| (11 significant bits: within 2⁻¹¹ of
// it); the sums are float32, in the order kernels::half_rows and half_columns fix (adjacency_kernels.hpp), the same
// bits on every instruction set.
//
// Why: the products stream every kept entry from memory, and with SPEC §17's rollouts (8 directions × 3 steps) the
// float32 copy is bound by its bytes (6 an entry per matrix). Here the n_hd matrices share one pattern, the union of
// the entries each keeps, and an entry holds its column (2 bytes) and n_hd weights (2 bytes each; 0 where that
// direction leaves the entry out): 18 bytes for 8 directions, against 48 for the same entry in 8 float32 matrices,
// and the eight directions' states of a cell are one load. The union holds 1.2–1.8× one matrix's entries at prune
// 10⁻² (docs/navigation.md#speed). The column form (Wᵀ·X = −W·X) needs an antisymmetric W, as learned; it serves
// states with few non-zero cells (a rollout's first step, from the place cells' rates). The entries are kept in
// tiles (kernels::HalfTiles: blocks of 64 rows, panels of 512 cells), so that a block reads the states of 512 cells
// (16 KB) at a time, which stay in the L1 cache; the sums, and so the bits, are those of whole rows.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "bvc3d/population/hd_adjacency.hpp"

namespace bvc3d {

namespace kernels {
struct HalfTiles;  // adjacency_kernels.hpp, a header of the library's own
}

class PackedAdjacency {
public:
    // panel: the tiles' width in cells (kernels::HalfTiles; n or more: whole rows, one tile a block).
    PackedAdjacency(const HdAdjacency& adj, double prune, int panel = 512);

    int n_place() const { return n_; }
    int n_hd() const { return n_hd_; }
    // y = (W_rec[k]·x[·][k])_k, x and y n × n_hd (row-major: x[j·n_hd + k]).
    void apply(std::span<const float> x, std::span<float> y) const;
    // Entries of the shared pattern, and the copy's bytes.
    std::size_t entries() const;
    double bytes() const;

private:
    // The tiles of the kept entries; fills factor_ and row_entries_ on the way.
    std::shared_ptr<const kernels::HalfTiles> pack(const HdAdjacency& adj, double prune, int panel);
    int n_, n_hd_;
    bool antisymmetric_;
    std::vector<std::uint32_t> row_entries_;           // per row: its entries (what a product by columns reads)
    std::vector<float> factor_;                        // per direction: scale · max|W_rec[k]|
    std::shared_ptr<const kernels::HalfTiles> tiles_;  // binary16 bits of w / max|W_rec[k]|, n_hd an entry, in tiles
};

}  // namespace bvc3d

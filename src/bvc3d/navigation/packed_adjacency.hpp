#pragma once
// Navigation stage: a frozen copy of a learned HD-conditioned adjacency (population/hd_adjacency.hpp) for the
// rollouts, all directions in one pass (the AdjacencyProduct interface, float32 states). Takes: the adjacency and
// `prune`. Gives: Y[i][k] = (W_rec[k]·X[·][k])_i, X and Y n × n_hd (row i holds cell i along every direction k).
//
// W_rec[k] keeps what SparseAdjacency keeps (|w| > prune·max|W_rec[k]|, others 0), each weight rounded to the
// nearest binary16 after dividing by max|W_rec[k]| (within 2⁻¹¹ of it); the n_hd matrices share one pattern (the
// union of the entries each keeps), an entry holding its column and n_hd weights, stored in tiles of 64 rows × 512
// cells (kernels::HalfTiles). The sums are float32 in the order kernels::half_rows and half_columns fix: the same bits
// on every instruction set. The column form (Wᵀ·X = −W·X) needs an antisymmetric W, as learned. Why this layout and
// what it gains: docs/navigation.md#speed and docs/performance.md#navigation-issue-30.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "bvc3d/navigation/adjacency_product.hpp"

namespace bvc3d {

namespace kernels {
struct HalfTiles;  // adjacency_kernels.hpp, a header of the library's own
}

class PackedAdjacency : public AdjacencyProduct {
public:
    // panel: the tiles' width in cells (kernels::HalfTiles; n or more: whole rows, one tile a block).
    PackedAdjacency(const HdAdjacency& adj, double prune, int panel = 512);

    int n_place() const override { return n_; }
    int n_dir() const override { return n_hd_; }
    int n_hd() const { return n_hd_; }
    StatePrecision precision() const override { return StatePrecision::float32; }
    // Every direction, whatever `which` asks for.
    void apply(std::span<const float> X, std::span<float> Y, std::span<const char> which = {}) const override;
    void apply(std::span<const double> X, std::span<double> Y, std::span<const char> which = {}) const override;
    // Entries of the shared pattern, and the copy's bytes.
    std::size_t entries() const override;
    double bytes() const override;

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

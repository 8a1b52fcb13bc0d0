#pragma once
// Navigation stage: a frozen copy of a learned HD-conditioned adjacency (population/hd_adjacency.hpp) in compressed
// rows, for replay and the float32 rollouts. Takes: the adjacency and `prune`. Gives: W[k]·x, per direction (the
// AdjacencyProduct interface: every direction at once).
//
// Per HD cell, the weights with |w| > prune·max|W[k]| (column index as uint16, float32 value: 6 bytes an entry, at
// most 65 536 place cells). With prune 0 a product gives the same bits as HdAdjacency::apply; pruned, the products of
// the matrices with the left-out weights set to 0, by columns where that reads under a third of the entries
// (by_columns), else each row in 16 lanes (adjacency_kernels.hpp). Why and how fast: docs/navigation.md#speed.
#include <cstdint>
#include <span>
#include <vector>

#include "bvc3d/navigation/adjacency_product.hpp"

namespace bvc3d {

// Whether a frozen copy's product is taken by columns (Wᵀ·x = −W·x, antisymmetric W only, over the rows of the
// non-zero cells: `work` entries of `entries`) rather than by rows: where that reads under a third of the entries.
inline bool by_columns(bool antisymmetric, std::size_t work, std::size_t entries) {
    return antisymmetric && 3 * work < entries;
}

class SparseAdjacency : public AdjacencyProduct {
public:
    explicit SparseAdjacency(const HdAdjacency& adj) : SparseAdjacency(adj, adj.params().prune) {}
    SparseAdjacency(const HdAdjacency& adj, double prune);

    int n_place() const override { return n_; }
    int n_dir() const override { return static_cast<int>(rows_.size()); }
    int n_hd() const { return n_dir(); }
    // out = W_rec[k]·x (n each).
    void apply(int k, std::span<const double> x, std::span<double> out) const;
    using AdjacencyProduct::apply;
    std::size_t entries() const override;
    double bytes() const override;
    // Each matrix's column sums of the kept weights, Σ_i W[k][i][j] (n_dir × n, row k): Σ_i (W[k]·x)_i = c_k·x.
    std::vector<double> column_sums() const;

protected:
    void apply_one(int k, std::span<const double> x, std::span<double> y) const override { apply(k, x, y); }

private:
    struct Rows {
        std::vector<std::uint32_t> start;  // n + 1 offsets into col and w
        std::vector<std::uint16_t> col;
        std::vector<float> w;
    };
    int n_;
    double scale_;
    bool antisymmetric_;
    bool pruned_;
    std::vector<Rows> rows_;
};

}  // namespace bvc3d

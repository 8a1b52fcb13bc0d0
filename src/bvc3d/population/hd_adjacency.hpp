#pragma once
// Population stage: the head-direction-conditioned adjacency of place cells (SPEC §16), what navigation
// (SPEC §17, docs/navigation.md) rolls forward to look ahead. Takes: place-cell rates v (n cells) and
// head-direction rates v_hd (n_hd cells) at each learning step. Gives: one transition matrix per HD cell,
// W_rec[k] (n × n), and products W_rec[k]·x.
//
// The update, per learning step (η = 0.096, τ_x = 3, τ_hd = 0.1, a = 0.3, δ = 10⁻⁴):
//   x   += (η/τ_x)(v − x)                  trace of the place cells
//   Υ   += (η/τ_hd)(v_hd − Υ)              trace of the HD cells
//   W_rec[k] += a·Υ_k·(v xᵀ − x vᵀ)        for each HD cell k, skipped on a step that bumps
//   W_rec[k] *= (1 − δ)                    every learning step (bumps too), after the update
// so W_rec[k][i][j] > 0 says "i follows j when heading along k": antisymmetric, as each update is. The
// traces are updated first and the update reads the new ones (SPEC's order). HD rates are SPEC §16's
// cells, v_k = cos(h − 2πk/n_hd) (hd_rates below), unless a model gives an HD population.
//
// Memory while learning: n_hd dense float32 matrices, n_hd·n²·4 bytes (8 HD cells: 2 MB for the paper's 250
// place cells, 128 MB for 2 000, 392 MB for 3 500): checked against the free memory before it is taken. The decay
// is a common scale factor (W = scale·M, folded back into M when it falls below 10⁻⁶), and the update touches
// only the rows and columns of the active cells: a step costs O(n_hd · active · n), not O(n_hd · n²).
//
// Products for navigation (replay, the rollouts) read a SparseAdjacency, a frozen copy in compressed rows (the
// rollouts, with `rollout_weights: float16`, a PackedAdjacency keeping the same weights: packed_adjacency.hpp). With
// `prune` = 0 (the default) it keeps every non-zero weight and gives exactly the dense products' bits. The trace x
// of a cell never returns to exactly 0 once it fired, so W_rec[k][i][j] becomes non-zero for nearly every pair of
// cells ever active within a few thousand steps of each other (the copy then holds ~all n² entries), but only the
// pairs active together within ~τ_x/η ≈ 30 steps carry weights near the largest. `prune` = p leaves out the
// weights with |w| ≤ p · max|W_rec[k]|: at p = 10⁻² the copy keeps 2–25 % of the entries (docs/performance.md),
// and the far cells no longer rise a hair above 0 in a rollout's tanh([Wx − x]+).
#include <cstdint>
#include <span>
#include <vector>

#include "bvc3d/core/params.hpp"
#include "bvc3d/population/population.hpp"

namespace bvc3d {

// The weights navigation's rollouts read: the float32 SparseAdjacency, or the PackedAdjacency (packed_adjacency.hpp).
enum class RolloutWeights { float32, float16 };

struct AdjacencyParams {
    int n_hd = 8;         // HD cells, one matrix each
    double eta = 0.096;   // η, as the place cells' Oja rule
    double tau_x = 3.0;   // place-cell trace: x += (η/τ_x)(v − x)
    double tau_hd = 0.1;  // HD trace: Υ += (η/τ_hd)(v_hd − Υ)
    double rate = 0.3;    // a in ΔW_rec[k] = a·Υ_k·(v xᵀ − x vᵀ)
    double decay = 1e-4;  // δ: every weight × (1 − δ) per learning step
    double prune = 0.0;   // products leave out |w| ≤ prune · max|W_rec[k]| (SparseAdjacency); 0: none
    RolloutWeights rollout_weights = RolloutWeights::float32;  // float16: the rollouts read a PackedAdjacency
    static const params::Table<AdjacencyParams>& table();
    void validate() const { table().check(*this); }
};

// SPEC §16's HD cells: n cells, v_k = cos(h − 2πk/n).
std::vector<double> hd_rates(double heading, int n = 8);

class HdAdjacency {
public:
    HdAdjacency(int n_place, const AdjacencyParams& params = {});

    int n_place() const { return n_; }
    int n_hd() const { return p_.n_hd; }
    const AdjacencyParams& params() const { return p_; }
    static double bytes(int n_place, int n_hd) { return double(n_hd) * n_place * n_place * sizeof(float); }

    // One learning step (see above): place rates v (n), HD rates (n_hd).
    void learn(std::span<const double> place, std::span<const double> hd, bool bumped);

    double weight(int k, int i, int j) const { return scale_ * m_[index(k, i, j)]; }
    // Sets every W_rec[k][i][j] (n_hd × n × n, row-major): hand-made adjacencies.
    void set_weights(std::span<const float> w);
    // out = W_rec[k]·x (n each).
    void apply(int k, std::span<const double> x, std::span<double> out) const;
    std::span<const double> place_trace() const { return x_; }
    std::span<const double> hd_trace() const { return u_; }

    // Everything to continue exactly (for checkpoints): the matrices (k, i, j), the scale and the traces.
    std::vector<StateArray> state() const;
    void restore(const std::vector<StateArray>& state);

private:
    std::size_t index(int k, int i, int j) const { return (std::size_t(k) * n_ + i) * n_ + j; }
    // What a frozen copy keeps (SparseAdjacency, PackedAdjacency): per matrix k, the stored weights m with
    // |m| > cut[k] = prune·top[k], top[k] = max|m| (the copy stays antisymmetric). Throws InputError naming the copy
    // if prune is outside [0, 1) or a uint16 column index cannot reach every cell.
    struct Kept {
        std::vector<float> top, cut;
    };
    Kept kept(double prune, const char* copy) const;
    int n_;
    AdjacencyParams p_;
    std::vector<float> m_;  // W_rec = scale_ · m_
    double scale_ = 1.0;
    bool antisymmetric_ = true;  // as learned; a hand-made W need not be
    std::vector<double> x_, u_;
    std::vector<int> active_;
    friend class SparseAdjacency;
    friend class PackedAdjacency;
};

// Whether a frozen copy's product is taken by columns (Wᵀ·x = −W·x, antisymmetric W only, over the rows of the
// non-zero cells: `work` entries of `entries`) rather than by rows: where that reads under a third of the entries.
inline bool by_columns(bool antisymmetric, std::size_t work, std::size_t entries) {
    return antisymmetric && 3 * work < entries;
}

// A frozen copy of an adjacency for products (see above): per HD cell, the weights with |w| > prune·max|W_rec[k]|
// in compressed rows (column index as uint16 and float32 value, 6 bytes an entry: at most 65 536 place cells; the
// products stream the entries from memory, so their size is their speed). With prune 0, apply() gives the same bits
// as HdAdjacency::apply; pruned, the products of the matrices with the left-out weights set to 0 (by columns where
// that reads under a third of the entries, else each row in 16 lanes: adjacency_kernels.hpp).
class SparseAdjacency {
public:
    explicit SparseAdjacency(const HdAdjacency& adj) : SparseAdjacency(adj, adj.params().prune) {}
    SparseAdjacency(const HdAdjacency& adj, double prune);

    int n_place() const { return n_; }
    int n_hd() const { return static_cast<int>(rows_.size()); }
    // out = W_rec[k]·x (n each).
    void apply(int k, std::span<const double> x, std::span<double> out) const;
    std::size_t entries() const;
    double bytes() const;

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

// The adjacency as a population of a model: reads the place cells (and an HD population, if a second input
// is given; else SPEC's 8 HD cells from the step's heading), learns on the learning steps, gives no rates;
// keeps its matrices at the end of a trial.
class AdjacencyPopulation : public Population {
public:
    AdjacencyPopulation(int n_place, const AdjacencyParams& params = {});
    HdAdjacency& adjacency() { return adj_; }
    std::size_t size() const override { return 0; }
    void step(const StepBlock& block, std::span<const std::span<const double>> inputs, std::span<double> out) override;
    std::vector<StateArray> state() const override { return adj_.state(); }
    void restore(const std::vector<StateArray>& state) override { adj_.restore(state); }
    std::vector<StateArray> kept() const override { return adj_.state(); }

private:
    HdAdjacency adj_;
};

}  // namespace bvc3d

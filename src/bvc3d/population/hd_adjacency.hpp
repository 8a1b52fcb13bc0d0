#pragma once
// Population stage: the head-direction-conditioned adjacency of place cells (SPEC §16), what navigation (SPEC §17,
// docs/navigation.md) rolls forward to look ahead. Takes: place-cell rates v (n cells) and head-direction rates v_hd
// (n_hd cells) at each learning step. Gives: one transition matrix per HD cell, W_rec[k] (n × n).
//
// The update, per learning step (η = 0.096, τ_x = 3, τ_hd = 0.1, a = 0.3, δ = 10⁻⁴):
//   x   += (η/τ_x)(v − x)                  trace of the place cells
//   Υ   += (η/τ_hd)(v_hd − Υ)              trace of the HD cells
//   W_rec[k] += a·Υ_k·(v xᵀ − x vᵀ)        for each HD cell k, skipped on a step that bumps
//   W_rec[k] *= (1 − δ)                    every learning step (bumps too), after the update
// so W_rec[k][i][j] > 0 says "i follows j when heading along k": antisymmetric, as each update is. The traces are
// updated first and the update reads the new ones (SPEC's order).
//
// Memory while learning: n_hd dense float32 matrices, n_hd·n²·4 bytes, checked against the free memory before it is
// taken. The decay is a common scale factor and the update touches only the rows and columns of the active cells
// (docs/navigation.md#the-adjacency). Navigation multiplies frozen copies of it (navigation/adjacency_product.hpp).
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
    friend class SparseAdjacency;  // navigation/: the frozen copies read the stored weights and the kept rule
    friend class PackedAdjacency;
    friend class ReferenceAdjacency;
};

// The adjacency as a population of a model (kind "adjacency"): reads a place-cell population and an HD population
// of n_hd cells, learns on the learning steps, gives no rates; keeps its matrices at the end of a trial.
class AdjacencyPopulation : public Population {
public:
    AdjacencyPopulation(int n_place, const AdjacencyParams& params = {});
    HdAdjacency& adjacency() { return adj_; }
    const HdAdjacency& adjacency() const { return adj_; }
    std::size_t size() const override { return 0; }
    void step(const StepBlock& block, std::span<const std::span<const double>> inputs, std::span<double> out) override;
    std::vector<StateArray> state() const override { return adj_.state(); }
    void restore(const std::vector<StateArray>& state) override { adj_.restore(state); }
    std::vector<StateArray> kept() const override { return adj_.state(); }

private:
    HdAdjacency adj_;
};

}  // namespace bvc3d

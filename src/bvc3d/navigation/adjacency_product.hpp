#pragma once
// Navigation stage: the one interface through which replay and the rollouts multiply a learned HD-conditioned
// adjacency (population/hd_adjacency.hpp) by states. Takes: the adjacency as learned and how a copy keeps it.
// Gives: Y = (W[k]·X[·, k])_k, every direction's matrix times its own column of an n × K state.
//
// Backends: ReferenceAdjacency (below: dense, plain loops, the definition), SparseAdjacency (float32 compressed rows,
// sparse_adjacency.hpp) and PackedAdjacency (binary16 weights on one pattern for all directions,
// packed_adjacency.hpp). All keep the weights |w| > prune·max|W[k]| of each matrix (others are 0); the fast ones are
// tested against the reference (test/unit/test_navigation.cpp). Which one the rollouts read is
// AdjacencyParams::rollout_weights (make_rollout_product).
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "bvc3d/population/hd_adjacency.hpp"

namespace bvc3d {

// The precision a copy keeps a rollout's state in between its steps: its fast path's own.
enum class StatePrecision { float64, float32 };

class AdjacencyProduct {
public:
    virtual ~AdjacencyProduct() = default;
    virtual int n_place() const = 0;
    virtual int n_dir() const = 0;
    virtual std::size_t entries() const = 0;  // weights kept, over all directions
    virtual double bytes() const = 0;         // of the copy
    virtual StatePrecision precision() const { return StatePrecision::float64; }
    // Y[i·K + k] = Σ_j W[k][i][j]·X[j·K + k] (K = n_dir()) for each direction k with which[k] set (every one if
    // `which` is empty); Y of the others is unspecified (a copy may compute every direction). Any copy takes both
    // forms, each in its own order of additions; a float32 copy's double form rounds X to float first.
    virtual void apply(std::span<const double> X, std::span<double> Y, std::span<const char> which = {}) const;
    virtual void apply(std::span<const float> X, std::span<float> Y, std::span<const char> which = {}) const;

protected:
    // y = W[k]·x for one direction: what the default all-directions forms call, one column at a time.
    virtual void apply_one(int k, std::span<const double> x, std::span<double> y) const;
    // InputError unless X and Y hold n_place() × n_dir() values and `which` is empty or one flag per direction.
    void check(std::size_t x, std::size_t y, std::size_t which) const;
};

// The definition: each matrix dense, the left-out weights 0, every row summed in column order in double.
class ReferenceAdjacency : public AdjacencyProduct {
public:
    ReferenceAdjacency(const HdAdjacency& adj, double prune);
    int n_place() const override { return n_; }
    int n_dir() const override { return n_dir_; }
    std::size_t entries() const override { return entries_; }
    double bytes() const override { return double(w_.size()) * sizeof(double); }

protected:
    void apply_one(int k, std::span<const double> x, std::span<double> y) const override;

private:
    int n_, n_dir_;
    std::size_t entries_ = 0;
    std::vector<double> w_;  // n_dir × n × n, the scale folded in
};

// The copy the rollouts read under `params` (rollout_weights: float32 → SparseAdjacency, float16 →
// PackedAdjacency), keeping |w| > params.prune·max|W[k]|.
std::unique_ptr<AdjacencyProduct> make_rollout_product(const HdAdjacency& adj, const AdjacencyParams& params);

}  // namespace bvc3d

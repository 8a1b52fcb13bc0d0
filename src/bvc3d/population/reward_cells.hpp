#pragma once
// Population stage: reward cells, replay and the choice of a direction (SPEC §17, docs/navigation.md).
// Takes: a learned HD-conditioned adjacency (hd_adjacency.hpp), the place cell bound to a goal, and the
// place-cell rates where the agent is. Gives: the reward cell's weights w (one per place cell), its
// read-out r at a state, and a value per HD direction.
//
//   replay (from the one-hot x₀ on the goal's cell), for t = 0 … ⌈8λ⌉:
//       w += A·e^{−t/λ}·x/|x|₂,   x ← tanh([max_k W_rec[k]·x + x]+)      (stops if x dies out)
//   read-out at rates v:   r(v) = w·v / max(|v|₁, 10⁻⁴)
//   direction k's return, rolling the state forward through W_rec[k] from x₀ = v:
//       x_{t+1} = tanh([W_rec[k]·x_t − x_t]+),   R_k = Σ_{t=0}^{T−1} γ^t r(x_{t+1})
// with λ = 20 and A = 5/λ (the authors' smallest scale), T = 3, γ = 0.7. The authors sample 10 rollouts
// per direction; the rollout here is deterministic, so one is all 10 would be (docs/navigation.md).
// Both read the adjacency's frozen sparse copy (hd_adjacency.hpp: weights below `prune` of the largest left out);
// the forms taking an HdAdjacency make that copy first (O(n_hd·n²)): navigation makes it once per learning run.
#include <span>
#include <vector>

#include "bvc3d/core/params.hpp"
#include "bvc3d/population/hd_adjacency.hpp"

namespace bvc3d {

struct RewardParams {
    double lambda = 20.0;    // λ: replay length ⌈8λ⌉ + 1 and its decay e^{−t/λ}
    double amplitude = 0.0;  // A; 0 means 5/λ
    int rollout_steps = 3;   // T
    double discount = 0.7;   // γ
    double beta = 500.0;     // directions are preferred by softmax(β·R)
    double amplitude_or_default() const { return amplitude > 0 ? amplitude : 5.0 / lambda; }
    static const params::Table<RewardParams>& table();
    void validate() const { table().check(*this); }
};

// The reward cell's weights after replay from place cell `goal_cell`.
std::vector<double> replay(const SparseAdjacency& adj, int goal_cell, const RewardParams& params = {});
std::vector<double> replay(const HdAdjacency& adj, int goal_cell, const RewardParams& params = {});
// r(v) = w·v / max(|v|₁, 10⁻⁴).
double reward(std::span<const double> w, std::span<const double> v);
// R_k for each HD direction k.
std::vector<double> direction_returns(const SparseAdjacency& adj, std::span<const double> w, std::span<const double> v,
                                      const RewardParams& params = {});
std::vector<double> direction_returns(const HdAdjacency& adj, std::span<const double> w, std::span<const double> v,
                                      const RewardParams& params = {});
// softmax(β·values) over the entries where `allowed` (others 0; all 0 if none is allowed).
std::vector<double> softmax(std::span<const double> values, double beta, const std::vector<char>& allowed);

}  // namespace bvc3d

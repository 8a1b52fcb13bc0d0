#pragma once
// Navigation stage: the rollouts of SPEC §17 (bvc3d's first controller: one straight rollout per direction). Takes: a
// frozen adjacency (adjacency_product.hpp), a reward cell's weights w and the place-cell rates v where the agent is.
// Gives: each HD direction's return
//       x₀ = v,   x_{t+1} = tanh([W_rec[k]·x_t − x_t]+),   R_k = Σ_{t=0}^{T−1} γ^t r(x_{t+1})
// with T = 3, γ = 0.7 and r the reward read-out (replay.hpp). The rollout is deterministic: one is what the authors'
// 10 samples of a straight rollout would all be (docs/navigation.md). Every direction is rolled at once, its state
// kept between steps in the copy's precision (double, or float32 for the packed copy); the tanh is SLEEF's
// (core/vector_math.hpp: the same bits on every instruction set).
#include <span>
#include <vector>

#include "bvc3d/navigation/adjacency_product.hpp"
#include "bvc3d/navigation/reward_params.hpp"

namespace bvc3d {

// R_k for each HD direction k; with `offered` (one flag per direction), 0 without a rollout's return where the flag
// is 0 (a direction the choice does not offer).
std::vector<double> direction_returns(const AdjacencyProduct& adj, std::span<const double> w, std::span<const double> v,
                                      const RewardParams& params = {}, std::span<const char> offered = {});
// The same through the adjacency's exact sparse copy (its own `prune`).
std::vector<double> direction_returns(const HdAdjacency& adj, std::span<const double> w, std::span<const double> v,
                                      const RewardParams& params = {});

}  // namespace bvc3d

#pragma once
// Navigation stage: replay from a goal's place cell and the reward cell's read-out (SPEC §17.1). Takes: a frozen
// adjacency (adjacency_product.hpp) and the place cell bound to a goal. Gives: the reward cell's weights w (one per
// place cell), and its read-out r at place-cell rates v.
//
//   replay, from the one-hot x₀ on the goal's cell, for t = 0 … ⌈8λ⌉ (stops if x dies out):
//       w += A·e^{−t/λ}·x/|x|₂,   x ← tanh([max_k W_rec[k]·x + x]+)
//   read-out:   r(v) = w·v / max(|v|₁, 10⁻⁴)
// λ = 20 and A = 5/λ for the authors' smallest scale (RewardParams::for_scale gives the others'). Replay keeps libm's
// tanh: its ⌈8λ⌉ steps of a recurrent map amplify last-place differences, and its weights stay as they were.
#include <span>
#include <vector>

#include "bvc3d/navigation/adjacency_product.hpp"
#include "bvc3d/navigation/reward_params.hpp"

namespace bvc3d {

// The reward cell's weights after replay from place cell `goal_cell` (InputError if it is not one).
std::vector<double> replay(const AdjacencyProduct& adj, int goal_cell, const RewardParams& params = {});
// The same through the adjacency's exact sparse copy (its own `prune`).
std::vector<double> replay(const HdAdjacency& adj, int goal_cell, const RewardParams& params = {});
// r(v) = w·v / max(|v|₁, 10⁻⁴): the reward cell's read-out (population/reward_cells.hpp, reward_readout).
double reward(std::span<const double> w, std::span<const double> v);

}  // namespace bvc3d

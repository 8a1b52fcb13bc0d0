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
// The rollouts' tanh is SLEEF's (core/vector_math.hpp: within 3.5 ulp, the same bits on every instruction set), many
// cells at a time; replay (once per goal) keeps libm's: its ⌈8λ⌉ steps of a recurrent map amplify last-place
// differences (to ~10⁻⁵ on a chain of cells), and its weights stay as they were.
// Both read the adjacency's frozen sparse copy (hd_adjacency.hpp: weights below `prune` of the largest left out), or
// the rollouts its packed copy (packed_adjacency.hpp: 16-bit weights, every direction in one pass; `adjacency:
// {rollout_weights: float16}`);
// the forms taking an HdAdjacency make that copy first (O(n_hd·n²)): navigation makes it once per learning run.
//
// Several scales (a multiscale model: each its place cells, adjacency, reward cell and λ — 20 / 30 / 60, SPEC §17)
// each give returns R_s; the choice combines them (combine_scales):
//       p_s = softmax(β·R_s)                          over the offered directions
//       c_s = mean R_s / max(H(p_s), 10⁻³)             mean over the offered directions; H the entropy in nats
//       ĉ_s = (1 − f)·ĉ_s + f·c_s                      smoothed over a start's decisions (f = 0.25; ĉ_s = c_s first)
//       P   = Σ_s α_s·p_s,   α = softmax(β_scale·ĉ)    β_scale = 2
// SPEC gives "softmax(2·score), score = mean return / entropy (smoothed, factor 0.25)"; the smoothing as an
// exponential average over decisions and the floor on the entropy (a scale sure of one direction has H → 0) are
// bvc3d's reading. With one scale, α = 1 and P = p exactly.
#include <span>
#include <vector>

#include "bvc3d/core/params.hpp"
#include "bvc3d/population/hd_adjacency.hpp"
#include "bvc3d/population/packed_adjacency.hpp"

namespace bvc3d {

struct RewardParams {
    double lambda = 20.0;    // λ: replay length ⌈8λ⌉ + 1 and its decay e^{−t/λ}
    double amplitude = 0.0;  // A; 0 means 5/λ
    int rollout_steps = 3;   // T
    double discount = 0.7;   // γ
    double beta = 500.0;     // directions are preferred by softmax(β·R)
    // Further scales of a multiscale model (the model's first scale takes `lambda`)
    std::vector<double> scale_lambdas{30.0, 60.0};  // λ of the second, third, ... scale (A = 5/λ unless `amplitude`)
    double scale_beta = 2.0;                        // scales are weighted by softmax(β_scale·score)
    double scale_smoothing = 0.25;                  // f: a scale's score smoothed over a start's decisions
    double amplitude_or_default() const { return amplitude > 0 ? amplitude : 5.0 / lambda; }
    // These parameters for scale s (0: the model's own place cells): its λ. InputError naming the key if
    // scale_lambdas has no value for it.
    RewardParams for_scale(std::size_t s) const;
    static const params::Table<RewardParams>& table();
    void validate() const { table().check(*this); }
};

// The reward cell's weights after replay from place cell `goal_cell`.
std::vector<double> replay(const SparseAdjacency& adj, int goal_cell, const RewardParams& params = {});
std::vector<double> replay(const HdAdjacency& adj, int goal_cell, const RewardParams& params = {});
// r(v) = w·v / max(|v|₁, 10⁻⁴).
double reward(std::span<const double> w, std::span<const double> v);
// R_k for each HD direction k; with `offered` (one flag per direction), 0 without a rollout where the flag is 0
// (a direction the choice does not offer: the softmaxes and the scales' scores read only the offered ones).
std::vector<double> direction_returns(const SparseAdjacency& adj, std::span<const double> w, std::span<const double> v,
                                      const RewardParams& params = {}, std::span<const char> offered = {});
std::vector<double> direction_returns(const HdAdjacency& adj, std::span<const double> w, std::span<const double> v,
                                      const RewardParams& params = {});
// The same through the packed copy (packed_adjacency.hpp: 16-bit weights, all directions at once): the states are
// stored in float32 between steps, the tanh and the read-out are computed in double as above.
std::vector<double> direction_returns(const PackedAdjacency& adj, std::span<const double> w, std::span<const double> v,
                                      const RewardParams& params = {}, std::span<const char> offered = {});
// softmax(β·values) over the entries where `allowed` (others 0; all 0 if none is allowed).
std::vector<double> softmax(std::span<const double> values, double beta, const std::vector<char>& allowed);

// The choice's probabilities over directions from each scale's returns (see above). `scores`: the smoothed scores ĉ,
// one per scale, carried from decision to decision (empty at a start's first decision; filled here).
std::vector<double> combine_scales(const std::vector<std::vector<double>>& returns, const std::vector<char>& allowed,
                                   const RewardParams& params, std::vector<double>& scores);

}  // namespace bvc3d

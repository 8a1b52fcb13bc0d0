#pragma once
// Navigation stage: the choice between directions, and between the scales of a multiscale model (SPEC §17). Takes:
// each scale's return per direction (rollouts.hpp) and which directions are offered. Gives: a probability per
// direction.
//
// Several scales (each its place cells, adjacency, reward cell and λ — 20 / 30 / 60) each give returns R_s:
//       p_s = softmax(β·R_s)                          over the offered directions
//       c_s = mean R_s / max(H(p_s), 10⁻³)             mean over the offered directions; H the entropy in nats
//       ĉ_s = (1 − f)·ĉ_s + f·c_s                      smoothed over a start's decisions (f = 0.25; ĉ_s = c_s first)
//       P   = Σ_s α_s·p_s,   α = softmax(β_scale·ĉ)    β_scale = 2
// SPEC gives "softmax(2·score), score = mean return / entropy (smoothed, factor 0.25)"; the smoothing as an
// exponential average over decisions and the floor on the entropy are bvc3d's reading. With one scale P = p exactly.
#include <span>
#include <vector>

#include "bvc3d/navigation/reward_params.hpp"

namespace bvc3d {

// softmax(β·values) over the entries where `allowed` (others 0; all 0 if none is allowed).
std::vector<double> softmax(std::span<const double> values, double beta, const std::vector<char>& allowed);

// The choice's probabilities over directions from each scale's returns (see above). `scores`: the smoothed scores ĉ,
// one per scale, carried from decision to decision (empty at a start's first decision; filled here).
std::vector<double> combine_scales(const std::vector<std::vector<double>>& returns, const std::vector<char>& allowed,
                                   const RewardParams& params, std::vector<double>& scores);

}  // namespace bvc3d

#pragma once
// Navigation stage: bvc3d's first controller (SPEC §17 as first written), a DirectionPolicy of the agent stage.
// Takes: per scale of place cells its frozen adjacency, reward parameters and each goal's reward-cell weights, the
// scales' current place-cell rates and a seeded stream. Gives: at each decision one of the offered directions, drawn
// from the scales' combined choice: per scale each direction's rollout return (rollouts.hpp), softmax(β·R), the
// scales weighted by their smoothed scores (scale_mix.hpp).
#include <memory>
#include <span>
#include <vector>

#include "bvc3d/agent/goal_seeking_walk.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/navigation/adjacency_product.hpp"
#include "bvc3d/navigation/reward_params.hpp"
#include "bvc3d/navigation/sparse_adjacency.hpp"

namespace bvc3d {

// What one scale gives the choice: its frozen copies (replay reads the float32 sparse one; the rollouts the one
// AdjacencyParams::rollout_weights names, which may be the same), its parameters and, per goal, its reward weights.
struct ScaleMemory {
    std::shared_ptr<const SparseAdjacency> sparse;
    std::shared_ptr<const AdjacencyProduct> rollouts;
    RewardParams reward;
    std::vector<std::vector<double>> rewards;  // per goal
};

// The scale's frozen copies of a learned adjacency under `params` (prune, rollout_weights).
ScaleMemory scale_memory(const HdAdjacency& adj, const AdjacencyParams& params, const RewardParams& reward);

class RolloutPolicy : public DirectionPolicy {
public:
    // `rates`: each scale's place-cell rates where the agent is, kept current by the caller.
    RolloutPolicy(const std::vector<ScaleMemory>& scales, std::size_t goal,
                  const std::vector<std::vector<double>>& rates, const RewardParams& params, Rng& rng);
    int choose(const Pose& pose, std::span<const char> allowed) override;

private:
    const std::vector<ScaleMemory>& scales_;
    std::size_t goal_;
    const std::vector<std::vector<double>>& rates_;
    RewardParams p_;
    Rng& rng_;
    std::vector<double> scores_;  // each scale's smoothed score over this start's decisions
};

}  // namespace bvc3d

#pragma once
// Navigation stage: what one scale of place cells gives navigation's choice after learning (SPEC §17). Takes: a
// learned adjacency (population/hd_adjacency.hpp), how its copies keep it (prune, rollout_weights) and the scale's
// reward parameters. Gives: its frozen copies — the float32 sparse one replay reads, the one the rollouts read (the
// same, or the 16-bit packed one) — and, once replay has run, each goal's reward weights.
#include <memory>
#include <vector>

#include "bvc3d/navigation/adjacency_product.hpp"
#include "bvc3d/navigation/reward_params.hpp"
#include "bvc3d/navigation/sparse_adjacency.hpp"

namespace bvc3d {

struct ScaleMemory {
    std::shared_ptr<const SparseAdjacency> sparse;
    std::shared_ptr<const AdjacencyProduct> rollouts;
    std::vector<double> column_sums;  // the sparse copy's (SparseAdjacency::column_sums): a turning rollout's logits
    AdjacencyParams adjacency;        // how the copies keep the adjacency (prune, rollout_weights)
    RewardParams reward;
    std::vector<std::vector<double>> rewards;  // per goal
};

// The scale's frozen copies of a learned adjacency under `params` (prune, rollout_weights).
ScaleMemory scale_memory(const HdAdjacency& adj, const AdjacencyParams& params, const RewardParams& reward);
// The copies made again from `adj` as it is now (a policy that learns while it exploits), the rest kept.
void refresh_copies(ScaleMemory& memory, const HdAdjacency& adj);

}  // namespace bvc3d

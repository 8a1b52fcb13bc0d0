#include "bvc3d/navigation/scale_memory.hpp"

namespace bvc3d {

ScaleMemory scale_memory(const HdAdjacency& adj, const AdjacencyParams& params, const RewardParams& reward) {
    ScaleMemory m;
    m.sparse = std::make_shared<const SparseAdjacency>(adj, params.prune);
    if (params.rollout_weights == RolloutWeights::float32) m.rollouts = m.sparse;
    else m.rollouts = make_rollout_product(adj, params);
    m.reward = reward;
    return m;
}

}  // namespace bvc3d

#include "bvc3d/navigation/scale_memory.hpp"

namespace bvc3d {

ScaleMemory scale_memory(const HdAdjacency& adj, const AdjacencyParams& params, const RewardParams& reward) {
    ScaleMemory m;
    m.adjacency = params;
    m.reward = reward;
    refresh_copies(m, adj);
    return m;
}

void refresh_copies(ScaleMemory& m, const HdAdjacency& adj) {
    m.sparse = std::make_shared<const SparseAdjacency>(adj, m.adjacency.prune);
    if (m.adjacency.rollout_weights == RolloutWeights::float32) m.rollouts = m.sparse;
    else m.rollouts = make_rollout_product(adj, m.adjacency);
    m.column_sums = m.sparse->column_sums();
}

}  // namespace bvc3d

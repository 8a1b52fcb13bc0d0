#include "bvc3d/navigation/rollout_policy.hpp"

#include "bvc3d/navigation/rollouts.hpp"
#include "bvc3d/navigation/scale_mix.hpp"

namespace bvc3d {

ScaleMemory scale_memory(const HdAdjacency& adj, const AdjacencyParams& params, const RewardParams& reward) {
    ScaleMemory m;
    m.sparse = std::make_shared<const SparseAdjacency>(adj, params.prune);
    if (params.rollout_weights == RolloutWeights::float32) m.rollouts = m.sparse;
    else m.rollouts = make_rollout_product(adj, params);
    m.reward = reward;
    return m;
}

RolloutPolicy::RolloutPolicy(const std::vector<ScaleMemory>& scales, std::size_t goal,
                             const std::vector<std::vector<double>>& rates, const RewardParams& params, Rng& rng)
    : scales_(scales), goal_(goal), rates_(rates), p_(params), rng_(rng) {}

int RolloutPolicy::choose(const Pose&, std::span<const char> allowed) {
    std::vector<std::vector<double>> returns;
    for (std::size_t s = 0; s < scales_.size(); ++s)
        returns.push_back(
            direction_returns(*scales_[s].rollouts, scales_[s].rewards[goal_], rates_[s], scales_[s].reward, allowed));
    const auto prob = combine_scales(returns, {allowed.begin(), allowed.end()}, p_, scores_);
    const double u = rng_.uniform();
    double sum = 0;
    int last = -1;
    for (std::size_t d = 0; d < prob.size(); ++d) {
        if (!allowed[d]) continue;
        last = static_cast<int>(d);
        if (u < (sum += prob[d])) return last;
    }
    return last;
}

}  // namespace bvc3d

#include "bvc3d/navigation/reward_params.hpp"

namespace bvc3d {

const params::Table<RewardParams>& RewardParams::table() {
    using namespace params;
    static const Table<RewardParams> t(
        "reward",
        {real("lambda", &RewardParams::lambda, closed(0.1, 1e4), "λ of replay: ⌈8λ⌉ + 1 steps decaying as e^{−t/λ}"),
         real("amplitude", &RewardParams::amplitude, closed(0, 1e6), "A of replay; 0: 5/λ"),
         integer("rollout_steps", &RewardParams::rollout_steps, closed(1, 100), "steps of each direction's rollout"),
         real("discount", &RewardParams::discount, closed(0, 1), "γ of the rollout's return"),
         real("beta", &RewardParams::beta, closed(0, 1e6), "directions are preferred by softmax(β·R)"),
         reals("scale_lambdas", &RewardParams::scale_lambdas, closed(0.1, 1e4),
               "λ of a multiscale model's second, third, ... scale (the first takes lambda)")
             .quiet_at_default(),
         real("scale_beta", &RewardParams::scale_beta, closed(0, 1e6), "scales are weighted by softmax(β·score)")
             .quiet_at_default(),
         real("scale_smoothing", &RewardParams::scale_smoothing, closed(0, 1),
              "a scale's score = mean return / entropy, averaged over decisions with this weight on the newest")
             .quiet_at_default()});
    return t;
}

RewardParams RewardParams::for_scale(std::size_t s) const {
    RewardParams p = *this;
    if (s == 0) return p;
    if (s > scale_lambdas.size())
        table().fail("scale_lambdas",
                     "gives λ for " + std::to_string(scale_lambdas.size() + 1) + " scales, but the model has more");
    p.lambda = scale_lambdas[s - 1];
    return p;
}

}  // namespace bvc3d

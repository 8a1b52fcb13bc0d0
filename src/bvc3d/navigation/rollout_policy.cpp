#include "bvc3d/navigation/rollout_policy.hpp"

#include <algorithm>

#include "bvc3d/navigation/rollouts.hpp"
#include "bvc3d/navigation/scale_mix.hpp"

namespace bvc3d {

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

namespace {

class RolloutController : public EpisodeController {
public:
    explicit RolloutController(const PolicyContext& c) : c_(c) {}
    StartRun run(const Pose& start, const StartTask& task, Rng& rng) override {
        const NavigationParams& p = c_.spec.nav;
        c_.senses.reset();
        for (int k = 0; k < std::max(1, p.settle_steps); ++k) c_.senses.step(start, false, 0.0);
        RolloutPolicy policy(c_.memory, task.goal, c_.senses.rates(), c_.reward, rng);
        const auto agent = c_.space.seeker(policy, start);
        StartRun out;
        out.path.push_back(start.position());
        while (true) {
            if (c_.space.distance(agent->pose().position(), task.at) <= task.success_radius) {
                out.end = StartEnd::reached;
                break;
            }
            if (agent->travelled() >= task.max_path_m) {
                out.end = StartEnd::path_cap;
                break;
            }
            const auto step = agent->next(task.max_s);
            if (!step) {
                out.end = agent->time() >= task.max_s ? StartEnd::time_cap : StartEnd::wedged;
                break;
            }
            c_.senses.step(step->pose, step->bumped, step->t);
            out.path.push_back(step->pose.position());
            out.bumped.push_back(step->bumped ? 1 : 0);
        }
        out.path_m = agent->travelled();
        out.time_s = agent->time();
        return out;
    }

private:
    PolicyContext c_;
};

}  // namespace

std::unique_ptr<EpisodeController> RolloutPolicySpec::make(const PolicyContext& context) const {
    return std::make_unique<RolloutController>(context);
}

}  // namespace bvc3d

#pragma once
// Navigation stage: bvc3d's first controller (SPEC §17 as first written; policy `rollout8`), a PolicySpec of
// policy.hpp. Takes: per scale of place cells its frozen adjacency, reward parameters and each goal's reward-cell
// weights, the scales' current place-cell rates and a seeded stream. Gives: at each decision one of the offered
// directions (the floor's 8 HD directions, or flying the 20 of the icosahedron), drawn from the scales' combined
// choice: per scale each direction's rollout return (rollouts.hpp), softmax(β·R), the scales weighted by their
// smoothed scores (scale_mix.hpp); the agent (NavigationSpace::seeker) turns to it and moves `step` m.
//
// A start: every population back to rest, `settle_steps` model steps at the start, then a decision and a model step
// per move until the goal is within the success radius, the path reaches its cap, the time runs out, or no direction
// is open. Learning is off.
#include <span>
#include <vector>

#include "bvc3d/agent/goal_seeking_walk.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/navigation/policy.hpp"

namespace bvc3d {

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

// The policy `rollout8` (no parameters of its own: navigation:'s step, clearance and settle_steps, reward:'s).
class RolloutPolicySpec : public PolicySpec {
public:
    static constexpr const char* kind = "rollout8";
    std::string name() const override { return kind; }
    std::string canonical(const std::string&) const override { return ""; }
    std::unique_ptr<EpisodeController> make(const PolicyContext& context) const override;
};

}  // namespace bvc3d

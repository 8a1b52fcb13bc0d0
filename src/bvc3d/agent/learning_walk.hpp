#pragma once
// Agent stage: the learning walk of navigation (SPEC §17.1). Takes: a navigation space's spec (its goals, the
// learning's criteria, the body) and a world. Gives: the space's random walk (the robot's, or the flying agent's),
// step for step, until `coverage` of the space's free cells of `coverage_cell` m are visited and each goal has been
// entered `goal_visits` times (within `goal_radius`), or until the trial's time runs out; then it has no steps left.
// Its report: the time of its last step (learn_s), the coverage reached and each goal's visits.
#include <memory>
#include <string>
#include <vector>

#include "bvc3d/agent/agent.hpp"
#include "bvc3d/agent/navigation_space.hpp"

namespace bvc3d {

class LearningWalkSpec : public AgentSpec {
public:
    explicit LearningWalkSpec(NavigationSpaceSpec spec);
    const NavigationSpaceSpec& spec() const { return spec_; }
    std::string kind() const override { return "learning_walk"; }
    Locomotion locomotion() const override { return walk_->locomotion(); }
    void validate() const override;
    // The walk's checks, and every goal's (NavigationSpace::check_goal).
    void check_world(const WorldDescription& world) const override;
    std::unique_ptr<Agent> make(const World* world, std::uint64_t seed) const override;
    std::string key() const override;
    double steps_per_second() const override { return walk_->steps_per_second(); }
    void write_yaml(params::CommentedYaml& out) const override { walk_->write_yaml(out); }
    int dims() const override { return walk_->dims(); }

private:
    NavigationSpaceSpec spec_;
    std::shared_ptr<const AgentSpec> walk_;
};

}  // namespace bvc3d

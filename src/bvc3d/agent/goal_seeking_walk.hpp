#pragma once
// Agent stage: the navigating agent's body (SPEC §17, docs/navigation.md). Takes: a world (through its
// BodyCollider), a start pose and a DirectionPolicy that chooses where to go. Gives: one model step per
// decision: the robot turns in place to the chosen one of n directions (0 = east, counter-clockwise) and
// drives forward `step` m, stopping at contact as the random walk's body does (random_walk.hpp).
//
// Directions with less than `clearance` m of free travel are not offered to the policy; if none has that
// much, those with the most free travel are. The policy lives above this stage: navigation reads the
// model's place cells to choose (experiment/navigation.hpp), and a test may steer by hand.
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "bvc3d/agent/agent.hpp"
#include "bvc3d/agent/body_collider.hpp"
#include "bvc3d/agent/random_walk.hpp"

namespace bvc3d {

class DirectionPolicy {
public:
    virtual ~DirectionPolicy() = default;
    // One of the n directions where allowed[d] is true (the agent is at `pose`).
    virtual int choose(const Pose& pose, std::span<const char> allowed) = 0;
};

// An agent that goes where a DirectionPolicy says: on the floor (GoalSeekingWalk) or flying
// (goal_seeking_flight.hpp). Navigation sees only this.
class GoalSeeker : public Agent {
public:
    virtual const Pose& pose() const = 0;
    virtual double travelled() const = 0;  // m
};

// The directions offered, given each direction's free travel (m): those with at least `clearance`, or, where
// none has it, those going as far as the farthest; none when every direction is blocked.
std::vector<char> offered_directions(std::span<const double> free, double clearance);

struct GoalSeekingParams {
    int n_dir = 8;           // directions 2πd/n_dir
    double step = 0.25;      // m per decision
    double clearance = 1.0;  // m of free travel a direction needs to be offered
};

class GoalSeekingWalk : public GoalSeeker {
public:
    // `robot` gives the body, the speed and the turn rate.
    GoalSeekingWalk(std::shared_ptr<const BodyCollider> body, const RobotParams& robot, const GoalSeekingParams& params,
                    DirectionPolicy& policy, const Pose& start);

    std::optional<ModelStep> next(double t_end) override;
    double time() const override { return t_; }
    const Pose& pose() const override { return pose_; }
    double travelled() const override { return travelled_; }  // m
    // The directions offered at p (see above).
    std::vector<char> allowed(const Vec2& p) const;
    std::string save_state() const override;
    void restore_state(const std::string& state) override;

private:
    std::shared_ptr<const BodyCollider> body_;
    RobotParams robot_;
    GoalSeekingParams p_;
    DirectionPolicy& policy_;
    Pose pose_;
    double t_ = 0.0, travelled_ = 0.0;
};

}  // namespace bvc3d

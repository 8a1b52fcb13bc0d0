#pragma once
// Agent stage: the flying navigating agent's body (SPEC §12 and §17, docs/navigation.md#flying-to-goals-in-3-d).
// Takes: a world with a flight volume (through its SphereCollider), the flight's parameters, a start pose, the unit
// directions it may fly (navigation gives the 20 flying HD cells' preferred directions) and a DirectionPolicy that
// chooses among them. Gives: one model step per decision: the agent turns to the chosen direction (taking
// |Δyaw|/turn_rate + |Δpitch|/turn_rate s, as the flying walk's turns) and flies `step` m along it at the flight's
// speed, stopping 1 nm short of contact as the flying walk's body does (flying_walk.hpp).
//
// Directions with less than `clearance` m of free travel are not offered to the policy; if none has that much,
// those with the most free travel are. The pose is the head's, as the flying walk gives it: at the body's centre,
// heading = the yaw of travel, level unless FlightParams::head says `body`.
#include <memory>
#include <vector>

#include "bvc3d/agent/flying_walk.hpp"
#include "bvc3d/agent/goal_seeking_walk.hpp"
#include "bvc3d/agent/sphere_collider.hpp"

namespace bvc3d {

struct FlyingSeekingParams {
    std::vector<Vec3> directions;  // unit vectors, the policy's choice indexes them
    double step = 0.25;            // m per decision
    double clearance = 1.0;        // m of free travel a direction needs to be offered
};

class FlyingGoalSeeker : public GoalSeeker {
public:
    FlyingGoalSeeker(std::shared_ptr<const SphereCollider> body, const FlightParams& flight, FlyingSeekingParams params,
                     DirectionPolicy& policy, const Pose& start);

    std::optional<ModelStep> next(double t_end) override;
    double time() const override { return t_; }
    const Pose& pose() const override { return pose_; }
    double travelled() const override { return travelled_; }
    // The directions offered at p (see above).
    std::vector<char> allowed(const Vec3& p) const;
    std::string save_state() const override;
    void restore_state(const std::string& state) override;

private:
    std::shared_ptr<const SphereCollider> body_;
    FlightParams flight_;
    FlyingSeekingParams p_;
    DirectionPolicy& policy_;
    Pose pose_;
    double pitch_ = 0.0;  // of the direction of travel (the pose's is 0 with a level head)
    double t_ = 0.0, travelled_ = 0.0;
};

}  // namespace bvc3d

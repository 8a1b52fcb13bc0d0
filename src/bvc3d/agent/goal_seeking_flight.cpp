#include "bvc3d/agent/goal_seeking_flight.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d {

FlyingGoalSeeker::FlyingGoalSeeker(std::shared_ptr<const SphereCollider> body, const FlightParams& flight,
                                   FlyingSeekingParams params, DirectionPolicy& policy, const Pose& start)
    : body_(std::move(body)),
      flight_(flight),
      p_(std::move(params)),
      policy_(policy),
      pose_(start),
      pitch_(start.pitch) {
    if (p_.directions.empty() || !(p_.step > 0))
        throw InputError("navigation: need at least one direction and a step > 0");
    for (Vec3& u : p_.directions) u.normalize();
}

std::vector<char> FlyingGoalSeeker::allowed(const Vec3& p) const {
    std::vector<double> free(p_.directions.size());
    for (std::size_t d = 0; d < free.size(); ++d) free[d] = body_->free_distance(p, p_.directions[d], p_.clearance);
    return offered_directions(free, p_.clearance);
}

std::optional<ModelStep> FlyingGoalSeeker::next(double t_end) {
    if (t_ >= t_end) return std::nullopt;
    const Vec3 p(pose_.x, pose_.y, pose_.z);
    const auto ok = allowed(p);
    if (std::none_of(ok.begin(), ok.end(), [](char c) { return c; })) return std::nullopt;  // wedged: cannot move
    const int d = policy_.choose(pose_, ok);
    if (d < 0 || std::size_t(d) >= ok.size() || !ok[std::size_t(d)])
        throw InputError("navigation: the policy chose a closed way");
    const Vec3& u = p_.directions[std::size_t(d)];
    const double yaw = std::atan2(u.y(), u.x()), pitch = std::asin(std::clamp(u.z(), -1.0, 1.0));
    t_ += (std::abs(wrap_pi(yaw - pose_.heading)) + std::abs(pitch - pitch_)) / flight_.turn_rate;
    const double free = body_->free_distance(p, u, p_.step);
    const double move = free >= p_.step ? p_.step : std::max(0.0, free - 1e-9);  // 1 nm short of contact
    const Vec3 q = p + move * u;
    pitch_ = pitch;
    pose_ = Pose{q.x(), q.y(), q.z(), yaw, flight_.head == FlightHead::body ? pitch : 0.0, 0.0};
    t_ += move / flight_.speed;
    travelled_ += move;
    return ModelStep{t_, pose_, move < p_.step, std::nullopt};
}

std::string FlyingGoalSeeker::save_state() const {
    std::ostringstream s;
    s.precision(17);
    s << pose_.x << ' ' << pose_.y << ' ' << pose_.z << ' ' << pose_.heading << ' ' << pose_.pitch << ' ' << pitch_
      << ' ' << t_ << ' ' << travelled_;
    return s.str();
}

void FlyingGoalSeeker::restore_state(const std::string& state) {
    std::istringstream s(state);
    Pose p;
    double pitch, t, d;
    if (!(s >> p.x >> p.y >> p.z >> p.heading >> p.pitch >> pitch >> t >> d))
        throw InputError("navigation: a saved state that does not fit");
    pose_ = p, pitch_ = pitch, t_ = t, travelled_ = d;
}

}  // namespace bvc3d

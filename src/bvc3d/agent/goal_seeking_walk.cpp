#include "bvc3d/agent/goal_seeking_walk.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d {

GoalSeekingWalk::GoalSeekingWalk(std::shared_ptr<const BodyCollider> body, const RobotParams& robot,
                                 const GoalSeekingParams& params, DirectionPolicy& policy, const Pose& start)
    : body_(std::move(body)), robot_(robot), p_(params), policy_(policy), pose_(start) {
    if (p_.n_dir < 1 || !(p_.step > 0)) throw InputError("navigation: need at least one direction and a step > 0");
}

std::vector<char> offered_directions(std::span<const double> free, double clearance) {
    const double most = *std::max_element(free.begin(), free.end());
    const double need = std::min(clearance, most);
    std::vector<char> ok(free.size());
    for (std::size_t d = 0; d < free.size(); ++d) ok[d] = most > 0 && free[d] >= need;
    return ok;
}

std::vector<char> GoalSeekingWalk::allowed(const Vec2& p) const {
    std::vector<double> free(std::size_t(p_.n_dir));
    for (int d = 0; d < p_.n_dir; ++d) {
        const double a = 2 * pi * d / p_.n_dir;
        free[std::size_t(d)] = body_->free_distance(p, Vec2(std::cos(a), std::sin(a)), p_.clearance);
    }
    return offered_directions(free, p_.clearance);
}

std::optional<ModelStep> GoalSeekingWalk::next(double t_end) {
    if (t_ >= t_end) return std::nullopt;
    const Vec2 p(pose_.x, pose_.y);
    const auto ok = allowed(p);
    if (std::none_of(ok.begin(), ok.end(), [](char c) { return c; })) return std::nullopt;  // wedged: cannot move
    const int d = policy_.choose(pose_, ok);
    if (d < 0 || d >= p_.n_dir || !ok[std::size_t(d)]) throw InputError("navigation: the policy chose a closed way");
    const double heading = wrap_pi(2 * pi * d / p_.n_dir);
    t_ += std::abs(wrap_pi(heading - pose_.heading)) / robot_.turn_rate;
    const Vec2 u(std::cos(heading), std::sin(heading));
    const double move = std::min(p_.step, body_->free_distance(p, u, p_.step));
    pose_ = Pose::on_floor(p.x() + move * u.x(), p.y() + move * u.y(), heading);
    t_ += move / robot_.speed;
    travelled_ += move;
    return ModelStep{t_, pose_, move < p_.step, std::nullopt};
}

std::string GoalSeekingWalk::save_state() const {
    std::ostringstream s;
    s.precision(17);
    s << pose_.x << ' ' << pose_.y << ' ' << pose_.heading << ' ' << t_ << ' ' << travelled_;
    return s.str();
}

void GoalSeekingWalk::restore_state(const std::string& state) {
    std::istringstream s(state);
    double x, y, h, t, d;
    if (!(s >> x >> y >> h >> t >> d)) throw InputError("navigation: a saved state that does not fit");
    pose_ = Pose::on_floor(x, y, h);
    t_ = t;
    travelled_ = d;
}

}  // namespace bvc3d

#include "bvc3d/navigation/authors_policy.hpp"

#include <cmath>

#include "bvc3d/agent/body_collider.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/world/ray_caster.hpp"

namespace bvc3d {

namespace {

class FloorBody : public AuthorsBody {
public:
    FloorBody(const World& world, const RobotParams& robot, const LidarSpec& sensor, ContactRule contact)
        : world_(world), body_(world.description(), robot.radius, robot.height), sensor_(sensor), contact_(contact) {}
    bool turn(Pose& pose, double heading) override {
        pose = Pose::on_floor(pose.x, pose.y, wrap_pi(heading));
        return true;
    }
    // Up to `step` along the heading; at contact (sliding) what is left of the step times the cosine between the
    // heading and the wall goes on along the wall, whose normal is the gradient of the body's clearance there (at
    // most two slides: a corner stops it).
    double forward(Pose& pose, double step) override {
        Vec2 p(pose.x, pose.y), u(std::cos(pose.heading), std::sin(pose.heading));
        double left = step, moved = 0;
        for (int leg = 0; leg < (contact_ == ContactRule::slide ? 3 : 1) && left > 1e-12; ++leg) {
            const double move = std::min(left, body_.free_distance(p, u, left));
            p += move * u, moved += move, left -= move;
            if (left <= 1e-12) break;
            const double h = 1e-5;
            Vec2 normal(body_.clearance(p + Vec2(h, 0)) - body_.clearance(p - Vec2(h, 0)),
                        body_.clearance(p + Vec2(0, h)) - body_.clearance(p - Vec2(0, h)));
            if (normal.norm() < 1e-12) break;
            normal.normalize();
            Vec2 along = u - u.dot(normal) * normal;
            if (along.norm() < 1e-6) break;  // head on: it stops
            left *= along.norm();
            u = along.normalized();
        }
        pose = Pose::on_floor(p.x(), p.y(), pose.heading);
        return moved;
    }
    std::vector<double> scan(const Pose& pose, int beams) const override {
        std::vector<Vec3> dirs;
        for (int j = 0; j < beams; ++j) {
            const double a = two_pi * j / beams;
            dirs.emplace_back(std::cos(a), std::sin(a), 0.0);
        }
        std::vector<double> ranges(dirs.size());
        world_.rays().cast(Vec3(pose.x, pose.y, pose.z + sensor_.height), dirs, sensor_.max_range, ranges);
        return ranges;
    }

private:
    const World& world_;
    BodyCollider body_;
    LidarSpec sensor_;
    ContactRule contact_;
};

}  // namespace

std::unique_ptr<AuthorsBody> floor_body(const World& world, const RobotParams& robot, const LidarSpec& sensor,
                                        ContactRule contact) {
    return std::make_unique<FloorBody>(world, robot, sensor, contact);
}

struct AuthorsController::Start {
    const StartTask& task;
    Rng& rng;
    Pose pose;
    double t = 0;
    bool contact = false;  // the last step stopped at contact (the bumpers' state)
    AuthorsReliability reliability;
    std::vector<double> H_prev;  // the smoothed entropies of the decision before (none at a start's first)
    StartRun out;
    bool done = false;
};

AuthorsController::AuthorsController(const PolicyContext& context, const AuthorsParams& params,
                                     std::unique_ptr<AuthorsBody> body)
    : c_(context), p_(params), body_(std::move(body)), live_(context.memory) {}

StartRun AuthorsController::run(const Pose& start, const StartTask& task, Rng& rng) {
    stats_ = {};
    if (p_.learn) c_.senses.reload();
    else c_.senses.reset();
    c_.senses.set_learning(p_.learn);
    Start s{task, rng, start, 0.0, false, AuthorsReliability(live_.size(), p_), {}, {}, false};
    s.out.path.push_back(start.position());
    for (int k = 0; k < p_.settle_steps; ++k) c_.senses.step(s.pose, false, s.t);
    while (!s.done) decide(s);
    stats_.full_turns = s.reliability.full_turns();
    stats_.loop_penalties = s.reliability.penalties();
    c_.senses.set_learning(false);
    s.out.time_s = s.t;
    return std::move(s.out);
}

bool AuthorsController::over(Start& s) {
    if (c_.space.distance(s.pose.position(), s.task.at) <= s.task.success_radius) s.out.end = StartEnd::reached;
    else if (s.out.path_m >= s.task.max_path_m) s.out.end = StartEnd::path_cap;
    else if (s.t >= s.task.max_s) s.out.end = StartEnd::time_cap;
    else return false;
    return s.done = true;
}

bool AuthorsController::step(Start& s) {
    c_.senses.step(s.pose, s.contact, s.t);
    return move(s);
}

bool AuthorsController::move(Start& s) {
    const double moved = body_->forward(s.pose, p_.step);
    s.contact = moved < p_.step;
    s.out.path_m += moved;
    s.t += p_.step / c_.spec.robot.speed;
    s.out.path.push_back(s.pose.position());
    s.out.bumped.push_back(s.contact ? 1 : 0);
    return over(s);
}

void AuthorsController::turn(Start& s, double heading, bool& completed) {
    s.t += std::abs(wrap_pi(heading - s.pose.heading)) / c_.spec.robot.turn_rate;
    completed = body_->turn(s.pose, heading);
    s.contact = false;  // turned away from what it touched
}

void AuthorsController::decide(Start& s) {
    c_.senses.step(s.pose, s.contact, s.t);
    if (over(s)) return;
    if (s.reliability.begin(rad_to_deg(s.pose.heading)) == AuthorsReliability::Phase::explore) {
        ++stats_.forced;
        explore(s);
        return;
    }
    const int n_dir = live_.front().rollouts->n_dir();
    const auto scan = body_->scan(s.pose, p_.scan_beams);
    std::vector<double> azimuths(scan.size());
    for (std::size_t j = 0; j < scan.size(); ++j) azimuths[j] = two_pi * double(j) / double(scan.size());
    const auto minima = sector_minima(scan, azimuths, n_dir, p_.sector);
    std::vector<DecisionScale> scales;
    const auto& rates = c_.senses.rates();
    for (std::size_t k = 0; k < live_.size(); ++k) {
        if (p_.learn && p_.refresh) refresh_copies(live_[k], c_.senses.adjacency(k));
        scales.push_back({live_[k].rollouts.get(), live_[k].column_sums, live_[k].rewards.at(s.task.goal), rates[k]});
    }
    std::vector<double> uniforms(rollout_uniforms(live_.size(), n_dir, p_));
    for (double& u : uniforms) u = s.rng.uniform();
    const AuthorsDecision d = authors_decide(scales, uniforms, minima, s.reliability.rho(), s.H_prev, p_);
    for (const auto& r : d.rollouts) stats_.products += r.products;
    s.H_prev = d.mix.H_smoothed;
    if (!d.choice) {
        ++stats_.unsafe;
        explore(s);
        return;
    }
    ++stats_.decisions;
    block(s, d.choice->heading);
    if (!s.done) s.reliability.end(d.choice->scale_weights, s.contact);
}

void AuthorsController::block(Start& s, double heading) {
    if (std::abs(wrap_pi(heading - s.pose.heading)) > p_.min_turn) {
        bool completed = true;
        turn(s, heading, completed);
        if (!completed) {
            failed_turn(s);
            return;
        }
    }
    for (int k = 0; k < p_.block_steps; ++k) {
        const bool ended = step(s);
        const double h = rad_to_deg(s.pose.heading);
        s.reliability.movement_headings({&h, 1});
        if (ended) return;
    }
}

void AuthorsController::failed_turn(Start& s) {
    ++stats_.failed_turns;
    const double by = -p_.failed_turn_max + 2 * p_.failed_turn_max * s.rng.uniform();
    bool completed = true;
    turn(s, s.pose.heading + by, completed);
    for (int k = 0; k < p_.failed_turn_steps; ++k)
        if (step(s)) return;
}

void AuthorsController::explore(Start& s) {
    bool completed = true;
    for (int k = 0; k < p_.explore_steps; ++k) {
        c_.senses.step(s.pose, s.contact, s.t);
        if (s.contact) {
            turn(s, s.pose.heading - pi + two_pi * s.rng.uniform(), completed);
            break;
        }
        if (move(s)) return;
    }
    turn(s, s.pose.heading + p_.explore_turn_sd * s.rng.normal(0.0, 1.0), completed);
}

std::string AuthorsPolicySpec::canonical(const std::string& indent) const {
    const std::string mine = params::yaml_lines(AuthorsParams::table(), p_, indent);
    return mine == params::yaml_lines(AuthorsParams::table(), AuthorsParams{}, indent) ? "" : mine;
}

void AuthorsPolicySpec::check_dims(int dims) const {
    if (dims != 2)
        throw InputError("policy 'authors' moves a robot on the floor (goals x,y); goals of " + std::to_string(dims) +
                         " coordinates need another policy");
}

std::unique_ptr<EpisodeController> AuthorsPolicySpec::make(const PolicyContext& context) const {
    return std::make_unique<AuthorsController>(
        context, p_, floor_body(context.world, context.spec.robot, context.sensor, p_.contact));
}

}  // namespace bvc3d

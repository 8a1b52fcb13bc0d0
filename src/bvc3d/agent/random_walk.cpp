#include "bvc3d/agent/random_walk.hpp"

#include <cmath>
#include <sstream>

#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/uniform_point.hpp"

namespace bvc3d {

const params::Table<RobotParams>& RobotParams::table() {
    using namespace params;
    static const Table<RobotParams> t(
        "robot", {real("radius", &RobotParams::radius, open_closed(0, 100), "m, the body's radius"),
                  real("height", &RobotParams::height, open_closed(0, 100), "m, the body's height"),
                  real("speed", &RobotParams::speed, open_closed(0, 1e3), "m/s, forward speed"),
                  real("turn_rate", &RobotParams::turn_rate, open_closed(0, 1e6), "rad/s, turning in place"),
                  real("model_dt", &RobotParams::model_dt, open_closed(0, 1e6), "s of forward motion per model step"),
                  integer("n_walk", &RobotParams::n_walk, closed(1, 1e9), "model steps between Gaussian turns"),
                  real("turn_sd", &RobotParams::turn_sd, closed(0, 100), "rad, sd of the Gaussian turn").in_radians(),
                  real("min_update_move", &RobotParams::min_update_move, closed(0, 1),
                       "m: a step cut short by a bump updates the model if it moved more"),
                  real("turn_control_step", &RobotParams::turn_control_step, closed(0, 10),
                       "s: > 0 turns in whole steps of this length, overshooting by up to one (0: exact turns)")
                      .quiet_at_default(),
                  flag("bump_gaussian_turn", &RobotParams::bump_gaussian_turn,
                       "after a bump's uniform heading, also make the Gaussian turn")
                      .quiet_at_default(),
                  flag("fixed_start_heading", &RobotParams::fixed_start_heading,
                       "start at start_heading (false: a uniform random heading)")
                      .quiet_at_default(),
                  real("start_heading", &RobotParams::start_heading, closed(-pi, pi),
                       "rad, the start heading when fixed_start_heading")
                      .in_radians()
                      .quiet_at_default(),
                  real("log_lag", &RobotParams::log_lag, closed(0, 10),
                       "s: each sample's position is where the robot is this long after its scan")
                      .quiet_at_default()});
    return t;
}

RobotParams RobotParams::authors() {
    RobotParams p;
    p.radius = 0.17;
    p.turn_rate = 1.83;
    p.turn_control_step = authors_control_step;
    p.bump_gaussian_turn = true;
    p.fixed_start_heading = true;
    p.start_heading = 0.0;
    return p;
}

RandomWalk::RandomWalk(std::shared_ptr<const BodyCollider> body, const RobotParams& params, Rng rng, const Pose& start)
    : body_(std::move(body)), p_(params), rng_(std::move(rng)) {
    p_.validate();
    state_.pose = start;
    state_.pose.heading = wrap_pi(start.heading);
}

Pose RandomWalk::draw_start(const WorldDescription& world, const BodyCollider& body, Rng& rng) {
    Pose pose;
    if (!world.start.points.empty()) {
        const auto n = world.start.points.size();
        const auto i = std::min(n - 1, static_cast<std::size_t>(rng.uniform() * static_cast<double>(n)));
        pose.x = world.start.points[i].x();
        pose.y = world.start.points[i].y();
        const std::string where =
            "world '" + world.name + "': start point (" + format_number(pose.x) + ", " + format_number(pose.y) + ")";
        if (!body.is_free(world.start.points[i]))
            throw InputError(where + " is blocked or outside the walkable region");
        if (!body.can_start_at(world.start.points[i])) {
            const auto [area, largest] = body.free_area(world.start.points[i]);
            throw InputError(where + " lies in a closed-off free area of " +
                             format_number(std::round(area * 100) / 100) + " m² (the largest is " +
                             format_number(std::round(largest * 100) / 100) + " m²): inside an obstacle?");
        }
    } else {
        const auto& region = world.start.region;
        if (region.points.size() < 3 || region.area() <= 0)
            throw InputError("world '" + world.name + "': no start points and no start region with positive area");
        const auto box = region.bounds();
        bool found = false;
        for (int attempt = 0; attempt < 100000 && !found; ++attempt) {
            const Vec2 p = uniform_point(box, rng);
            if (region.contains(p) && body.can_start_at(p)) {
                pose.x = p.x();
                pose.y = p.y();
                found = true;
            }
        }
        if (!found)
            throw InputError("world '" + world.name +
                             "': the start region has no place where the robot fits, "
                             "outside obstacles and closed-off pockets");
    }
    pose.heading = rng.uniform(-pi, pi);
    return pose;
}

namespace {

// An error about a key of the world's file (or, for a preset, of the world by name).
[[noreturn]] void world_key_error(const WorldDescription& world, const std::string& key, const std::string& reason) {
    if (world.file.empty()) throw InputError("world '" + world.name + "': " + key + ": " + reason);
    throw ConfigError(world.file, key, reason);
}

}  // namespace

void RandomWalk::check_start(const WorldDescription& world, const BodyCollider& body) {
    const double r = body.radius();
    const std::string robot = "robot.radius = " + format_number(r) + " m";
    const auto& points = world.start.points;
    if (!points.empty()) {
        double most_room = 0;
        bool all_blocked = true;
        for (const auto& p : points) {
            const bool inside = world.walkable.contains(p);
            if (inside) most_room = std::max(most_room, body.room(p));
            all_blocked = all_blocked && inside && !body.is_free(p);
        }
        // Room at some start point for the paper's robot, but none for this one: the robot is at fault.
        if (all_blocked && most_room >= RobotParams{}.radius)
            throw InputError(robot + " is too large for world '" + world.name + "': the robot fits at none of its " +
                             std::to_string(points.size()) + " start points (the most room around one is " +
                             format_number(std::round(most_room * 1000) / 1000) + " m)");
        for (std::size_t i = 0; i < points.size(); ++i) {
            const std::string key = "start.points[" + std::to_string(i) + "]";
            const Vec2& p = points[i];
            if (!world.walkable.contains(p))
                world_key_error(world, key, point_text(p) + " lies outside the walkable region");
            if (!body.is_free(p))
                world_key_error(world, key,
                                point_text(p) + " is blocked: a robot of radius " + format_number(r) +
                                    " m would overlap geometry there (room: " +
                                    format_number(std::round(body.room(p) * 1000) / 1000) + " m)");
            if (!body.can_start_at(p)) {
                const auto [area, largest] = body.free_area(p);
                world_key_error(world, key,
                                point_text(p) + " lies in a closed-off free area of " +
                                    format_number(std::round(area * 100) / 100) + " m² (the largest is " +
                                    format_number(std::round(largest * 100) / 100) +
                                    " m²): inside an obstacle, or a pocket the robot cannot leave");
            }
        }
        return;
    }
    const auto& region = world.start.region;
    if (region.points.size() < 3 || region.area() <= 0)
        world_key_error(world, "start", "no start points and no start region with positive area");
    if (body.can_start_in(region)) return;
    if (body.free_area(region.points.front()).second <= 0)
        throw InputError(robot + " is too large for world '" + world.name + "': the robot fits nowhere in it");
    world_key_error(world, world.file.empty() ? "start" : "start",
                    "the start region has no place where a robot of radius " + format_number(r) +
                        " m fits, outside obstacles and closed-off pockets");
}

void RandomWalk::turn_to(double heading) {
    if (p_.turn_control_step > 0) {
        // Whole control steps, until the heading has reached or passed the target.
        const double delta = wrap_pi(heading - state_.pose.heading);
        const double per_step = p_.turn_rate * p_.turn_control_step;
        const double steps = std::ceil(std::abs(delta) / per_step);
        state_.t += steps * p_.turn_control_step;
        state_.pose.heading = wrap_pi(state_.pose.heading + std::copysign(steps * per_step, delta));
        return;
    }
    heading = wrap_pi(heading);
    state_.t += std::abs(wrap_pi(heading - state_.pose.heading)) / p_.turn_rate;
    state_.pose.heading = heading;
}

void RandomWalk::bump() {
    const double h = rng_.uniform(-pi, pi);
    if (log_) log_->push_back({TurnEvent::Kind::bump, h});
    turn_to(h);
    if (p_.bump_gaussian_turn) {
        const double d = rng_.normal(0.0, p_.turn_sd);
        if (log_) log_->push_back({TurnEvent::Kind::gaussian, d});
        turn_to(state_.pose.heading + d);
    }
    state_.steps_since_turn = 0;
    state_.bump_pending = false;
}

std::optional<ModelStep> RandomWalk::next(double t_end) {
    auto step = walk(t_end, INFINITY);
    if (step && p_.log_lag > 0) step->logged_pose = pose_after(p_.log_lag);
    return step;
}

Pose RandomWalk::pose_after(double dt) const {
    RandomWalk ahead(*this);
    ahead.log_ = nullptr;
    const double t_stop = state_.t + dt;
    while (ahead.state_.t < t_stop) ahead.walk(t_stop, t_stop);
    Pose p = state_.pose;  // the heading and height of now, the position of `dt` later
    p.x = ahead.state_.pose.x;
    p.y = ahead.state_.pose.y;
    return p;
}

std::optional<ModelStep> RandomWalk::walk(double t_end, double stop_at) {
    const double step_len = p_.speed * p_.model_dt;
    int stuck = 0;  // bumps in a row without moving
    while (state_.t < t_end) {
        if (state_.bump_pending) {
            if (++stuck > 100000)
                throw InputError("the robot is stuck at (" + std::to_string(state_.pose.x) + ", " +
                                 std::to_string(state_.pose.y) + "): every heading is blocked");
            bump();
            continue;
        }
        if (state_.steps_since_turn >= p_.n_walk) {
            const double d = rng_.normal(0.0, p_.turn_sd);
            if (log_) log_->push_back({TurnEvent::Kind::gaussian, d});
            turn_to(state_.pose.heading + d);
            state_.steps_since_turn = 0;
            continue;
        }
        Pose& q = state_.pose;
        const Vec2 u(std::cos(q.heading), std::sin(q.heading));
        const double free = body_->free_distance(Vec2(q.x, q.y), u, step_len);
        const double reach = free >= step_len ? step_len : std::max(0.0, free - 1e-9);
        const double duration = free >= step_len ? p_.model_dt : reach / p_.speed;
        if (state_.t + duration > stop_at) {  // part of this move, at constant speed
            const double d = std::min(reach, p_.speed * (stop_at - state_.t));
            q.x += d * u.x();
            q.y += d * u.y();
            state_.t = stop_at;
            return std::nullopt;
        }
        if (free >= step_len) {
            q.x += step_len * u.x();
            q.y += step_len * u.y();
            state_.t += p_.model_dt;
            ++state_.steps_since_turn;
            return ModelStep{state_.t, q, false, std::nullopt};
        }
        // Bumper: stop at contact (a nanometre short of it), then turn to a uniform heading.
        const double moved = std::max(0.0, free - 1e-9);
        q.x += moved * u.x();
        q.y += moved * u.y();
        state_.t += moved / p_.speed;
        state_.bump_pending = true;
        if (moved > p_.min_update_move) return ModelStep{state_.t, q, true, std::nullopt};
    }
    return std::nullopt;
}

WalkState RandomWalk::state() const {
    WalkState s = state_;
    s.rng_state = rng_.state();
    return s;
}

void RandomWalk::restore(const WalkState& s) {
    rng_.set_state(s.rng_state);  // first: it may throw, and then nothing has changed
    state_ = s;
}

std::string RandomWalk::save_state() const {
    const WalkState w = state();
    std::ostringstream os;
    os << "random_walk " << format_number(w.pose.x) << ' ' << format_number(w.pose.y) << ' '
       << format_number(w.pose.heading) << ' ' << format_number(w.t) << ' ' << w.steps_since_turn << ' '
       << (w.bump_pending ? 1 : 0) << '\n'
       << w.rng_state;
    return os.str();
}

void RandomWalk::restore_state(const std::string& text) {
    std::istringstream is(text);
    std::string kind, x, y, heading, t;
    WalkState w;
    int bump = 0;
    is >> kind >> x >> y >> heading >> t >> w.steps_since_turn >> bump;
    if (!is || kind != "random_walk") throw InputError("saved state is not a random walk's");
    try {
        w.pose = Pose::on_floor(std::stod(x), std::stod(y), std::stod(heading));
        w.t = std::stod(t);
    } catch (const std::exception&) {
        throw InputError("saved random-walk state is corrupt");
    }
    w.bump_pending = bump != 0;
    is.ignore(1);
    w.rng_state.assign(std::istreambuf_iterator<char>(is), {});
    restore(w);
}

void RandomWalkSpec::check_world(const WorldDescription& world) const {
    if (world.walkable.points.empty() && world.flight)
        throw InputError("world '" + world.name +
                         "' is a flight-only world (no walkable region): the random walk's "
                         "robot cannot use it; use the flying agent (trial key flight:, --agent flight)");
    validate();
    RandomWalk::check_start(world, BodyCollider(world, robot_.radius, robot_.height));
}

std::unique_ptr<Agent> RandomWalkSpec::make(const World* world, std::uint64_t seed) const {
    validate();
    if (!world) throw InputError("the random walk needs a world to walk in");
    if (world->description().walkable.points.empty() && world->description().flight) check_world(world->description());
    auto body = std::make_shared<const BodyCollider>(world->description(), robot_.radius, robot_.height);
    RandomWalk::check_start(world->description(), *body);
    Rng rng(seed, Stream::walk);
    Pose start = RandomWalk::draw_start(world->description(), *body, rng);
    if (robot_.fixed_start_heading) start.heading = robot_.start_heading;  // the start point is still drawn
    return std::make_unique<RandomWalk>(body, robot_, std::move(rng), start);
}

std::string RandomWalkSpec::key() const { return "robot:\n" + params::yaml_lines(RobotParams::table(), robot_, "  "); }

void RandomWalkSpec::write_yaml(params::CommentedYaml& out) const {
    out.section("", "robot", "the random walk's robot (or, instead, trajectory: FILE, a given path)");
    out.fields(RobotParams::table(), robot_, "  ");
}

std::vector<ModelStep> random_walk(const World& world, double hours, std::uint64_t seed, const RobotParams& params) {
    if (!std::isfinite(hours) || hours < 0) throw InputError("walk: hours must be >= 0, got " + format_number(hours));
    if (hours > max_agent_hours)
        throw InputError("walk: hours = " + format_number(hours) + " is more than the limit of " +
                         format_number(max_agent_hours) + " simulated hours");
    params.validate();
    const auto walk = RandomWalkSpec(params).make(&world, seed);
    std::vector<ModelStep> steps;
    steps.reserve(static_cast<std::size_t>(hours * 3600 / params.model_dt) + 16);
    while (auto s = walk->next(hours * 3600.0)) {
        steps.push_back(*s);
        if (steps.size() % 4096 == 0) poll_cancel();
    }
    return steps;
}

}  // namespace bvc3d

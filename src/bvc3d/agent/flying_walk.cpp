#include "bvc3d/agent/flying_walk.hpp"

#include <cmath>
#include <sstream>

#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/uniform_point.hpp"

namespace bvc3d {

const params::Table<FlightParams>& FlightParams::table() {
    using namespace params;
    using F = FlightParams;
    static const Table<F> t(
        "flight",
        {real("radius", &F::radius, open_closed(0, 100), "m, the body is a sphere of this radius"),
         real("speed", &F::speed, open_closed(0, 1e3), "m/s along the direction of flight"),
         real("turn_rate", &F::turn_rate, open_closed(0, 1e6), "rad/s, for yaw and for pitch turns"),
         real("model_dt", &F::model_dt, open_closed(0, 1e6), "s of motion per model step"),
         integer("n_walk", &F::n_walk, closed(1, 1e9), "model steps between Gaussian turns"),
         real("yaw_sd", &F::yaw_sd, closed(0, 100), "rad, sd of the Gaussian yaw turn").in_radians(),
         real("pitch_sd", &F::pitch_sd, closed(0, 100), "rad, sd of the Gaussian pitch turn").in_radians(),
         real("max_pitch", &F::max_pitch, closed(0, pi / 2), "rad, the largest |pitch| of the direction of flight")
             .in_radians(),
         real("min_update_move", &F::min_update_move, closed(0, 1),
              "m: a step cut short by a bump updates the model if it moved more"),
         choice("head", &F::head, {{FlightHead::level, "level"}, {FlightHead::body, "body"}},
                "level (a stabilized head: the sensor stays level) or body (it pitches with the body)")});
    return t;
}

FlyingWalk::FlyingWalk(std::shared_ptr<const SphereCollider> body, const FlightParams& params, Rng rng,
                       const FlightState& start)
    : body_(std::move(body)), p_(params), rng_(std::move(rng)), state_(start) {
    p_.validate();
    state_.yaw = wrap_pi(start.yaw);
}

FlightState FlyingWalk::draw_start(const SphereCollider& body, const FlightParams& params, Rng& rng,
                                   const std::string& world_name) {
    FlightState s;
    const auto& box = body.center_box();
    bool found = false;
    for (int attempt = 0; attempt < 100000 && !found; ++attempt) {
        const Vec3 p = uniform_point(box, rng);
        if (body.can_start_at(p)) {
            s.position = p;
            found = true;
        }
    }
    if (!found)
        throw InputError("world '" + world_name + "': the flight volume has no place where the body (radius " +
                         format_number(body.radius()) + " m) fits, outside obstacles and closed-off pockets");
    s.yaw = rng.uniform(-pi, pi);
    const double lim = std::sin(params.max_pitch);
    s.pitch = std::asin(rng.uniform(-lim, lim));
    return s;
}

Pose FlyingWalk::pose() const {
    const Vec3& c = state_.position;
    return Pose{c.x(), c.y(), c.z(), state_.yaw, p_.head == FlightHead::body ? state_.pitch : 0.0, 0.0};
}

void FlyingWalk::turn_to(double yaw, double pitch) {
    yaw = wrap_pi(yaw);
    state_.t += (std::abs(wrap_pi(yaw - state_.yaw)) + std::abs(pitch - state_.pitch)) / p_.turn_rate;
    state_.yaw = yaw;
    state_.pitch = pitch;
}

void FlyingWalk::bump() {
    // A direction uniform on the sphere within the pitch limits: sin(pitch) is uniform.
    const double yaw = rng_.uniform(-pi, pi);
    const double lim = std::sin(p_.max_pitch);
    const double pitch = std::asin(rng_.uniform(-lim, lim));
    if (log_) log_->push_back({FlightTurn::Kind::bump, yaw, pitch});
    turn_to(yaw, pitch);
    state_.steps_since_turn = 0;
    state_.bump_pending = false;
}

std::optional<ModelStep> FlyingWalk::next(double t_end) {
    const double step_len = p_.speed * p_.model_dt;
    int stuck = 0;  // bumps in a row without moving
    while (state_.t < t_end) {
        if (state_.bump_pending) {
            if (++stuck > 100000) {
                const Vec3& c = state_.position;
                throw InputError("the flying agent is stuck at (" + format_number(c.x()) + ", " + format_number(c.y()) +
                                 ", " + format_number(c.z()) + "): every direction is blocked");
            }
            bump();
            continue;
        }
        if (state_.steps_since_turn >= p_.n_walk) {
            const double dyaw = rng_.normal(0.0, p_.yaw_sd);
            const double dpitch = rng_.normal(0.0, p_.pitch_sd);
            if (log_) log_->push_back({FlightTurn::Kind::gaussian, dyaw, dpitch});
            turn_to(state_.yaw + dyaw, std::clamp(state_.pitch + dpitch, -p_.max_pitch, p_.max_pitch));
            state_.steps_since_turn = 0;
            continue;
        }
        const double cp = std::cos(state_.pitch);
        const Vec3 u(cp * std::cos(state_.yaw), cp * std::sin(state_.yaw), std::sin(state_.pitch));
        const double free = body_->free_distance(state_.position, u, step_len);
        if (free >= step_len) {
            state_.position += step_len * u;
            state_.t += p_.model_dt;
            ++state_.steps_since_turn;
            return ModelStep{state_.t, pose(), false, std::nullopt};
        }
        // Contact: stop a nanometre short of it, then fly off in a new direction.
        const double moved = std::max(0.0, free - 1e-9);
        state_.position += moved * u;
        state_.t += moved / p_.speed;
        state_.bump_pending = true;
        if (moved > p_.min_update_move) return ModelStep{state_.t, pose(), true, std::nullopt};
    }
    return std::nullopt;
}

FlightState FlyingWalk::state() const {
    FlightState s = state_;
    s.rng_state = rng_.state();
    return s;
}

void FlyingWalk::restore(const FlightState& s) {
    state_ = s;
    rng_.set_state(s.rng_state);
}

std::string FlyingWalk::save_state() const {
    const FlightState s = state();
    std::ostringstream os;
    os << "flight " << format_number(s.position.x()) << ' ' << format_number(s.position.y()) << ' '
       << format_number(s.position.z()) << ' ' << format_number(s.yaw) << ' ' << format_number(s.pitch) << ' '
       << format_number(s.t) << ' ' << s.steps_since_turn << ' ' << (s.bump_pending ? 1 : 0) << '\n'
       << s.rng_state;
    return os.str();
}

void FlyingWalk::restore_state(const std::string& text) {
    std::istringstream is(text);
    std::string kind, x, y, z, yaw, pitch, t;
    FlightState s;
    int bump = 0;
    is >> kind >> x >> y >> z >> yaw >> pitch >> t >> s.steps_since_turn >> bump;
    if (!is || kind != "flight") throw InputError("saved state is not a flying agent's");
    try {
        s.position = Vec3(std::stod(x), std::stod(y), std::stod(z));
        s.yaw = std::stod(yaw);
        s.pitch = std::stod(pitch);
        s.t = std::stod(t);
    } catch (const std::exception&) {
        throw InputError("saved flight state is corrupt");
    }
    s.bump_pending = bump != 0;
    is.ignore(1);
    s.rng_state.assign(std::istreambuf_iterator<char>(is), {});
    restore(s);
}

void FlightSpec::check_world(const WorldDescription& world) const {
    if (!world.flight) {
        const std::string reason =
            "the world has no flight volume, so a flying agent cannot use it (a ground world: "
            "use the random walk's robot, or declare flight_volume in the world's YAML)";
        if (world.file.empty()) throw InputError("world '" + world.name + "': " + reason);
        throw ConfigError(world.file, "flight_volume", reason);
    }
    validate();
    try {
        const SphereCollider fits(world, flight_.radius);  // throws for a volume that cannot hold the body
        (void)fits;
    } catch (const InputError& e) {
        // The body is the trial's (flight.radius), the volume the world's: name both, the radius first.
        if (dynamic_cast<const ConfigError*>(&e)) throw;
        throw InputError("flight.radius " + format_number(flight_.radius) + " m: " + e.what() +
                         "; give a smaller flight.radius or a larger flight_volume" +
                         (world.file.empty() ? std::string() : " (world file '" + world.file + "')"));
    }
}

std::unique_ptr<Agent> FlightSpec::make(const World* world, std::uint64_t seed) const {
    validate();
    if (!world) throw InputError("the flying walk needs a world to fly in");
    check_world(world->description());
    auto body = std::make_shared<const SphereCollider>(world->description(), flight_.radius);
    Rng rng(seed, Stream::walk);
    const FlightState start = FlyingWalk::draw_start(*body, flight_, rng, world->name());
    return std::make_unique<FlyingWalk>(body, flight_, std::move(rng), start);
}

std::string FlightSpec::key() const { return "flight:\n" + params::yaml_lines(FlightParams::table(), flight_, "  "); }

void FlightSpec::write_yaml(params::CommentedYaml& out) const {
    out.section("", "flight", "the flying agent (docs/flying.md): a sphere on a 3-D random walk");
    out.fields(FlightParams::table(), flight_, "  ");
}

std::vector<ModelStep> flying_walk(const World& world, double hours, std::uint64_t seed, const FlightParams& params) {
    if (!std::isfinite(hours) || hours < 0) throw InputError("flight: hours must be >= 0");
    if (hours > max_agent_hours)
        throw InputError("flight: hours = " + format_number(hours) + " is more than the limit of " +
                         format_number(max_agent_hours) + " simulated hours");
    const auto walk = FlightSpec(params).make(&world, seed);
    std::vector<ModelStep> steps;
    steps.reserve(static_cast<std::size_t>(hours * 3600 / params.model_dt) + 16);
    while (auto s = walk->next(hours * 3600.0)) {
        steps.push_back(*s);
        if (steps.size() % 4096 == 0) poll_cancel();
    }
    return steps;
}

}  // namespace bvc3d

#pragma once
// The flying agent and its 3-D random walk (docs/flying.md#the-flying-agent).
// Takes: a World with a flight volume (through its SphereCollider) and a seeded random stream.
// Gives: the model steps of the flight, as an Agent. A step's pose is the agent's head: at the
// body's center, heading = the yaw of travel, level (pitch 0) unless FlightParams::head says `body`.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bvc3d/agent/agent.hpp"
#include "bvc3d/agent/sphere_collider.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/params.hpp"
#include "bvc3d/core/random.hpp"

namespace bvc3d {

// Whether the sensor on the head stays level while the body pitches (a stabilized head: the scan's
// rows keep their elevations, so a model casts only the rows it needs) or pitches with the body.
enum class FlightHead { level, body };

struct FlightParams {
    double radius = 0.2;            // m, the body is a sphere
    double speed = 1.0;             // m/s along the direction of flight
    double turn_rate = 2.1;         // rad/s, for yaw and for pitch
    double model_dt = 0.288;        // s of motion per model step (0.288 m)
    int n_walk = 10;                // model steps between Gaussian turns
    double yaw_sd = pi / 6;         // rad, sd of the Gaussian yaw turn
    double pitch_sd = pi / 12;      // rad, sd of the Gaussian pitch turn
    double max_pitch = pi / 3;      // rad, |pitch| never exceeds it
    double min_update_move = 1e-3;  // m: a step cut short by a bump updates if it moved more
    FlightHead head = FlightHead::level;

    static const params::Table<FlightParams>& table();
    void validate() const { table().check(*this); }
};

// Every turn the flight draws, for checking its distributions.
struct FlightTurn {
    enum class Kind { gaussian, bump } kind;
    double yaw;    // gaussian: the drawn yaw change; bump: the new absolute yaw
    double pitch;  // gaussian: the drawn pitch change (before clipping); bump: the new absolute pitch
};

// Everything needed to continue a flight exactly where it stopped.
struct FlightState {
    Vec3 position = Vec3::Zero();  // the body's center
    double yaw = 0.0, pitch = 0.0;
    double t = 0.0;
    int steps_since_turn = 0;
    bool bump_pending = false;
    std::string rng_state;
};

class FlyingWalk : public Agent {
public:
    FlyingWalk(std::shared_ptr<const SphereCollider> body, const FlightParams& params, Rng rng,
               const FlightState& start);

    // A uniformly random start: a uniform point of the flight volume where the body fits (outside
    // solid obstacles and closed-off pockets), a direction uniform on the sphere within the pitch limits.
    static FlightState draw_start(const SphereCollider& body, const FlightParams& params, Rng& rng,
                                  const std::string& world_name);

    std::optional<ModelStep> next(double t_end) override;
    double time() const override { return state_.t; }
    std::string save_state() const override;
    void restore_state(const std::string& state) override;

    FlightState state() const;
    void restore(const FlightState& s);
    void log_turns(std::vector<FlightTurn>* log) { log_ = log; }

private:
    Pose pose() const;
    void turn_to(double yaw, double pitch);
    void bump();

    std::shared_ptr<const SphereCollider> body_;
    FlightParams p_;
    Rng rng_;
    FlightState state_;
    std::vector<FlightTurn>* log_ = nullptr;
};

// The flying agent as a trial's agent (trial YAML key `flight:`).
class FlightSpec : public AgentSpec {
public:
    explicit FlightSpec(FlightParams flight = {}) : flight_(flight) {}
    const FlightParams& flight() const { return flight_; }
    std::string kind() const override { return "flight"; }
    Locomotion locomotion() const override { return Locomotion::flying; }
    void validate() const override { flight_.validate(); }
    std::unique_ptr<Agent> make(const World* world, std::uint64_t seed) const override;
    std::string key() const override;
    double steps_per_second() const override { return 1.0 / flight_.model_dt; }
    void write_yaml(params::CommentedYaml& out) const override;
    int dims() const override { return 3; }
    void check_world(const WorldDescription& world) const override;

private:
    FlightParams flight_;
};

// A whole flight of `hours` simulated hours from a seeded random start.
std::vector<ModelStep> flying_walk(const World& world, double hours, std::uint64_t seed,
                                   const FlightParams& params = {});

}  // namespace bvc3d

#pragma once
// The ground robot and its random walk (docs/model-reference.md#robot-and-random-walk).
// Takes: a World (through its BodyCollider) and a seeded random stream.
// Gives: the model steps of the walk, as an Agent.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bvc3d/agent/agent.hpp"
#include "bvc3d/agent/body_collider.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/params.hpp"
#include "bvc3d/core/random.hpp"

namespace bvc3d {

struct RobotParams {
    double radius = 0.25;           // m (the paper's 0.5 m diameter)
    double height = 0.10;           // m
    double speed = 0.5;             // m/s forward
    double turn_rate = 2.1;         // rad/s, in place
    double model_dt = 0.288;        // s of forward motion per model step (0.144 m)
    int n_walk = 10;                // model steps between Gaussian turns (the paper's τ_w)
    double turn_sd = pi / 6;        // rad, sd of the Gaussian turn
    double min_update_move = 1e-3;  // m: a step cut short by a bump updates if it moved more
    // Options for robots that differ from the paper's (docs/reproduction.md#the-authors-configuration);
    // at their defaults the walk is the paper's.
    double turn_control_step = 0.0;    // s: > 0 turns in whole steps of this length until the target is
                                       // reached or passed (overshooting by less than one step)
    bool bump_gaussian_turn = false;   // after a bump's uniform heading, also make the Gaussian turn
    bool fixed_start_heading = false;  // start at start_heading instead of a uniform heading
    double start_heading = 0.0;        // rad, with fixed_start_heading
    double log_lag = 0.0;              // s: each sample is logged where the robot is this long after its scan

    // The robot of the authors' Webots code: radius 0.17 m, turns at 1.83 rad/s in 96 ms control
    // steps, the Gaussian turn after a bump too, a fixed start heading (east). Its logging lag is
    // a separate choice (authors_log_lag).
    static RobotParams authors();
    static constexpr double authors_control_step = 0.096;                // s
    static constexpr double authors_log_lag = 2 * authors_control_step;  // s: two control steps, ≈0.1 m

    static const params::Table<RobotParams>& table();
    void validate() const { table().check(*this); }
};

// Every turn the walk draws, for checking its distributions.
struct TurnEvent {
    enum class Kind { gaussian, bump } kind;
    double drawn;  // gaussian: the turn angle; bump: the new absolute heading
};

// Everything needed to continue a walk exactly where it stopped.
struct WalkState {
    Pose pose;
    double t = 0.0;
    int steps_since_turn = 0;
    bool bump_pending = false;
    std::string rng_state;
};

class RandomWalk : public Agent {
public:
    RandomWalk(std::shared_ptr<const BodyCollider> body, const RobotParams& params, Rng rng, const Pose& start);

    // A uniformly random start: one of the world's start points (or a free point of its start
    // region) and a uniform heading.
    static Pose draw_start(const WorldDescription& world, const BodyCollider& body, Rng& rng);
    // Every start point (or the start region) has room for this body, or an InputError blaming the
    // robot's radius (it fits at none) or the world's start point or region (it alone is bad).
    static void check_start(const WorldDescription& world, const BodyCollider& body);

    std::optional<ModelStep> next(double t_end) override;
    double time() const override { return state_.t; }
    std::string save_state() const override;
    void restore_state(const std::string& state) override;

    const Pose& pose() const { return state_.pose; }
    WalkState state() const;
    void restore(const WalkState& s);
    void log_turns(std::vector<TurnEvent>* log) { log_ = log; }

private:
    // Walks until a model step ends (returned) or, when `stop_at` comes first, stops where the
    // robot is at `stop_at`, part way through a move (nullopt). next(t_end) is walk(t_end, ∞).
    std::optional<ModelStep> walk(double t_end, double stop_at);
    // Where the robot will be `dt` seconds from now on the path it takes (the same draws).
    Pose pose_after(double dt) const;
    void turn_to(double heading);
    void bump();

    std::shared_ptr<const BodyCollider> body_;
    RobotParams p_;
    Rng rng_;
    WalkState state_;
    std::vector<TurnEvent>* log_ = nullptr;
};

// The random walk as a trial's agent: the robot's parameters, a start drawn from the seed.
class RandomWalkSpec : public AgentSpec {
public:
    explicit RandomWalkSpec(RobotParams robot = {}) : robot_(robot) {}
    const RobotParams& robot() const { return robot_; }
    std::string kind() const override { return "random_walk"; }
    Locomotion locomotion() const override { return Locomotion::ground; }
    void validate() const override { robot_.validate(); }
    void check_world(const WorldDescription& world) const override;
    std::unique_ptr<Agent> make(const World* world, std::uint64_t seed) const override;
    std::string key() const override;
    double steps_per_second() const override { return 1.0 / robot_.model_dt; }
    void write_yaml(params::CommentedYaml& out) const override;

private:
    RobotParams robot_;
};

// A whole walk of `hours` simulated hours from a seeded random start.
std::vector<ModelStep> random_walk(const World& world, double hours, std::uint64_t seed,
                                   const RobotParams& params = {});

}  // namespace bvc3d

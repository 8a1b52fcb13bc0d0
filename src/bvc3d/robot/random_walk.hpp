#pragma once
// The robot and its random walk (SPEC §4).
// Takes: a World (through its BodyCollider) and a seeded random stream.
// Gives: the model steps: where and when the place-cell model is updated.
#include <memory>
#include <optional>
#include <vector>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/robot/body_collider.hpp"
#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d {

struct RobotParams {
    double radius = 0.25;                  // m (the paper's 0.5 m diameter)
    double height = 0.10;                  // m
    double speed = 0.5;                    // m/s forward
    double turn_rate = 2.1;                // rad/s, in place
    double model_dt = 0.288;               // s of forward motion per model step (0.144 m)
    int n_walk = 10;                       // model steps between Gaussian turns (the paper's τ_w)
    double turn_sd = pi / 6;               // rad, sd of the Gaussian turn
    double min_update_move = 1e-3;         // m: a step cut short by a bump updates if it moved more
    void validate() const;
};

// One model update.
struct WalkStep {
    double t;  // simulated seconds since the start of the walk
    double x, y, heading;
    bool bumped;  // the step ended at a contact
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

class RandomWalk {
public:
    RandomWalk(std::shared_ptr<const BodyCollider> body, const RobotParams& params, Rng rng, const Pose& start);

    // A uniformly random start: one of the world's start points (or a free point of its start
    // region) and a uniform heading.
    static Pose draw_start(const WorldDescription& world, const BodyCollider& body, Rng& rng);

    // Moves until the next model update and returns it; nullopt once simulated time reaches t_end
    // (a step begun before t_end is completed).
    std::optional<WalkStep> next(double t_end);

    const Pose& pose() const { return state_.pose; }
    double time() const { return state_.t; }
    WalkState state() const;
    void restore(const WalkState& s);
    void log_turns(std::vector<TurnEvent>* log) { log_ = log; }

private:
    void turn_to(double heading);
    void bump();

    std::shared_ptr<const BodyCollider> body_;
    RobotParams p_;
    Rng rng_;
    WalkState state_;
    std::vector<TurnEvent>* log_ = nullptr;
};

// A whole walk of `hours` simulated hours from a seeded random start.
std::vector<WalkStep> random_walk(const World& world, double hours, std::uint64_t seed, const RobotParams& params = {});

}  // namespace bvc3d

#pragma once
// Agent stage: where the agent goes.
// Takes: a World (for collision) and a seed, or a given path (which needs no world). Gives: the model steps — when and
// at which pose the model is updated — one at a time, and its state as text for checkpoints.
// Kinds of agent: the ground robot's random walk (random_walk.hpp), a given trajectory (trajectory.hpp) and the flying
// agent (flying_walk.hpp), registered in config/agent_kinds.hpp. The trial runner, checkpoints and walk sharing see
// only this interface; other stages ask a spec what it can do (dims(), locomotion()), never which kind it is.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bvc3d/core/geometry.hpp"
#include "bvc3d/core/params.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

// The longest an agent may run, in simulated hours (2500 times the paper's 4 h): a longer walk or
// protocol phase is refused before it starts, with this number.
inline constexpr double max_agent_hours = 1e4;

// One model update: its time and the agent's pose (a ground robot's pose is its base on the floor).
struct ModelStep {
    double t = 0.0;  // seconds since the agent started
    Pose pose;
    bool bumped = false;  // the step ended at a contact
    // Where the sample is logged when that is not `pose` (a logging lag): the model still sees
    // the world from `pose`.
    std::optional<Pose> logged_pose;
    const Pose& logged() const { return logged_pose ? *logged_pose : pose; }
};

class Agent {
public:
    virtual ~Agent() = default;
    // The next model step, or nullopt once time() has reached t_end (a step begun before t_end is
    // completed) or the agent has no steps left.
    virtual std::optional<ModelStep> next(double t_end) = 0;
    virtual double time() const = 0;
    // No steps left at any t_end (a trajectory's end; a random walk never finishes).
    virtual bool finished() const { return false; }
    // Everything needed to continue exactly where it stopped.
    virtual std::string save_state() const = 0;
    virtual void restore_state(const std::string& state) = 0;  // InputError if it does not fit
    // What the agent reports of its run, as named numbers (a learning walk: the coverage it reached, each goal's
    // visits); a name may repeat, one value per item.
    virtual std::vector<std::pair<std::string, double>> report() const { return {}; }
};

// How an agent moves, which decides the model presets made for it: on the floor (the ground robot's
// presets: the scanner above the floor), flying (the fly-* presets: the scanner at the body's center,
// looking down too), or along a given path (any preset: the path is the data).
enum class Locomotion { ground, flying, given_path };

// A kind of agent and its parameters: what a trial configuration holds. Trials whose agents have
// equal key() in the same world with the same seed take the same steps, so they can share them.
class AgentSpec {
public:
    virtual ~AgentSpec() = default;
    virtual std::string kind() const = 0;  // its name in config/agent_kinds.hpp: "random_walk", "trajectory", "flight"
    virtual Locomotion locomotion() const = 0;
    virtual void validate() const = 0;  // InputError naming the bad parameter
    // Whether the agent can run in this world (a random walk: every start point has room for the
    // robot, and the world has a floor to walk on; a trajectory: every row lies inside the world; a
    // flying agent: the world has a flight volume that holds its body): InputError naming the world's key
    // (`start.points[1]`) or the agent's (`robot.radius`), whichever is at fault. make() checks it too.
    virtual void check_world(const WorldDescription& world) const = 0;
    // `world` may be null (a replay of recorded data has none) for agents that do not need one;
    // the others throw InputError.
    virtual std::unique_ptr<Agent> make(const World* world, std::uint64_t seed) const = 0;
    // Configuration text that fixes the steps: the YAML a trial file records.
    virtual std::string key() const = 0;
    // Model steps per second of agent time, on average (for buffer sizes and duration checks).
    virtual double steps_per_second() const = 0;
    // The trial YAML keys that give this agent back (`robot:` and its keys, `trajectory: FILE`), with
    // their descriptions (`bvc3d config`); InputError if there are none (a path given as arrays).
    virtual void write_yaml(params::CommentedYaml& out) const = 0;
    // Coordinates of the positions the analysis bins: 2 (x, y) for agents on the floor, 3 (x, y, z)
    // for flying ones.
    virtual int dims() const { return 2; }
    // What a reader of a run's output must know about how this agent steps the model (a trajectory
    // resampled to the model step); empty when there is nothing to say.
    virtual std::string note() const { return {}; }
};

}  // namespace bvc3d

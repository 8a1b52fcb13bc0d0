#pragma once
// Navigation stage: the seam through which controllers enter navigation (SPEC §17, docs/navigation.md#policies).
// Takes: what one start needs — the model to step (NavigationSenses), where the agent moves (the world and its
// NavigationSpace), each scale's memories (scale_memory.hpp: frozen adjacencies, reward weights) and a seeded stream.
// Gives: one start run (EpisodeController::run): the agent's path, whether it reached the goal, how far and how long
// it went, and why it stopped.
//
// A policy is a PolicySpec: its name, its parameters' canonical text (in the trial's fingerprint), what it needs of
// the episodes, and the controller it makes. The kinds are one list, config/policy_kinds.hpp, which navigate's
// --policy, YAML's policy: and Python's policy= read. The episodes (experiment/episodes.hpp) see only these
// interfaces: a new controller is a PolicySpec and its EpisodeController in one file of this stage, its test, and a
// row of that list.
#include <memory>
#include <string>
#include <vector>

#include "bvc3d/agent/navigation_space.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/navigation/scale_memory.hpp"
#include "bvc3d/sensor/lidar.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

// The model as a controller steps it: the trial's populations, one model step at a time (the experiment stage's).
class NavigationSenses {
public:
    virtual ~NavigationSenses() = default;
    // One model step at `pose` (`bumped`: the body touched geometry on the way there) at agent time `t`: each scale's
    // place-cell rates after it (the same object every call, kept current).
    virtual const std::vector<std::vector<double>>& step(const Pose& pose, bool bumped, double t) = 0;
    virtual const std::vector<std::vector<double>>& rates() const = 0;
    // Every population back to rest (a new start), what it learned kept.
    virtual void reset() = 0;
    // Every population set back to its state at the end of learning, activity included: a start of a policy that
    // learns while it exploits begins where learning ended (PolicySpec::learns).
    virtual void reload() = 0;
    // Whether the model steps learn (Oja, the adjacency): off unless a policy that learns turns it on.
    virtual void set_learning(bool on) = 0;
    // Scale s's adjacency as it is now (learning changes it): what a policy that learns reads afresh.
    virtual const HdAdjacency& adjacency(std::size_t s) const = 0;
};

// One start's goal and limits.
struct StartTask {
    std::size_t goal = 0;         // its index among the goals (each scale's reward weights)
    Vec3 at = Vec3::Zero();       // where it is
    double success_radius = 1.0;  // m: reached within this (NavigationSpace::distance)
    double max_path_m = 0.0;      // m: fails when the path reaches this
    double max_s = 0.0;           // s of agent time: fails after this
};

// Why a start ended.
enum class StartEnd { reached, path_cap, time_cap, wedged };

struct StartRun {
    StartEnd end = StartEnd::time_cap;
    double path_m = 0.0, time_s = 0.0;
    std::vector<Vec3> path;    // positions: the start, then one per move of the agent
    std::vector<char> bumped;  // per position after the start: the move touched geometry
    bool success() const { return end == StartEnd::reached; }
};

class EpisodeController {
public:
    virtual ~EpisodeController() = default;
    // One start from `start` (the model is stepped here, from rest or reloaded, as the policy says).
    virtual StartRun run(const Pose& start, const StartTask& task, Rng& rng) = 0;
};

// What a controller is made from; it keeps the references.
struct PolicyContext {
    const World& world;
    const NavigationSpace& space;
    const NavigationSpaceSpec& spec;  // goals, navigation's parameters, the bodies
    NavigationSenses& senses;
    const std::vector<ScaleMemory>& memory;  // per scale
    const RewardParams& reward;              // navigation's reward: table (the first scale's)
    const LidarSpec& sensor;                 // the model's sensor (its height and range: a policy's own scans)
};

class PolicySpec {
public:
    virtual ~PolicySpec() = default;
    virtual std::string name() const = 0;
    // InputError (a ParamError naming the key) for parameters out of range.
    virtual void validate() const {}
    // Its parameters as YAML lines at `indent` for the trial's canonical text; "" while all hold their defaults.
    virtual std::string canonical(const std::string& indent) const = 0;
    // InputError when it cannot move in a space of goals of `dims` coordinates.
    virtual void check_dims(int dims) const { (void)dims; }
    // Whether it learns while it exploits: the episodes then keep the learned state, and every start reloads it.
    virtual bool learns() const { return false; }
    virtual std::unique_ptr<EpisodeController> make(const PolicyContext& context) const = 0;
};

}  // namespace bvc3d

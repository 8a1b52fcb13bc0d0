#pragma once
// Experiment stage: navigation to goals (SPEC §17, docs/navigation.md), the closed loop from place cells to
// motion. Takes: a world, a model (its sensor, BVC layer and place cells), goals on the floor (x, y) or in the
// air (x, y, z: the flying agent) and a seed. Gives: per goal, its reward cell; per start, whether and how the
// agent reached the goal, against the shortest path (agent/shortest_path.hpp; in 3-D agent/voxel_path.hpp).
//
// Where the agent moves is a NavigationSpace (navigation.cpp), picked by the goals' dimension: on the floor (the
// paper's robot, its random walk, 8 HD cells of the heading, the floor's grid) or flying (SPEC §12's body and walk,
// the 20 flying HD cells of the direction of motion, 0.5 m voxels for coverage, voxels for the shortest path; see
// docs/navigation.md#flying-to-goals-in-3-d). The loop below sees only the space.
//
// Learning: the paper's random walk (agent/random_walk.hpp) while the place cells learn (Oja) and the
// HD-conditioned adjacency learns (population/hd_adjacency.hpp), until `coverage` of the free cells of
// `coverage_cell` m are visited and each goal has been entered `goal_visits` times (goal radius), or
// `max_learn_hours`. The place cell most active inside a goal's radius during learning is its reward
// cell. Exploitation, per goal: replay from the reward cell (population/reward_cells.hpp); from each of
// `starts` random starts at least `min_start_distance` m from the goal (Euclidean, in the goal's part of
// the floor), the agent (agent/goal_seeking_walk.hpp) chooses each 0.25 m move by softmax(β·R) over the
// directions' rollout returns R, sampled from its seeded stream, until it is within `success_radius` of
// the goal, or its path reaches `max_path_ratio` × the shortest path, or `max_hours` pass.
//
// The model is stepped through its populations (experiment/model_network.hpp, one step at a time), and each of
// its scales of place cells (ModelSpec::place_scales: the paper's model has one, ms-2d and ms-3d three) learns its
// own adjacency and binds its own reward cell; replay and the rollouts run per scale (λ per scale:
// RewardParams::for_scale) and the choice combines the scales' returns (combine_scales, SPEC §17:
// softmax(2·score)), see docs/navigation.md#multiscale. With one scale the choice is softmax(β·R) exactly. A run
// reports the first scale's reward cells and reward map.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "bvc3d/agent/flying_walk.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/core/params.hpp"
#include "bvc3d/population/hd_adjacency.hpp"
#include "bvc3d/population/reward_cells.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

struct NavigationParams {
    // learning
    double coverage = 0.95;       // fraction of free cells visited
    double coverage_cell = 0.5;   // m
    int goal_visits = 10;         // entries into each goal's radius
    double goal_radius = 0.7;     // m
    double max_learn_hours = 15;  // simulated
    // exploitation
    int starts = 20;                  // per goal
    double min_start_distance = 6.0;  // m from the goal
    double success_radius = 1.0;      // m
    double max_path_ratio = 10.0;     // fail when the path reaches this × the shortest
    double max_hours = 5.0;           // simulated, per start
    double step = 0.25;               // m per decision
    double clearance = 1.0;           // m a direction needs
    int settle_steps = 5;             // place-cell steps at a start before the first decision
    // the yardstick (SPEC §17): A* on this grid, obstacles inflated by this
    double path_cell = 0.1;        // m
    double path_inflate = 0.5;     // m
    double reward_map_cell = 0.5;  // m between the points of the reward maps; 0: none
    static const params::Table<NavigationParams>& table();
    void validate() const { table().check(*this); }
};

// A goal: on the floor (x, y; dims 2) or in the air (x, y, z; dims 3: the flying agent). All goals of a run have
// the same dimension.
struct NavigationGoal {
    Vec3 p = Vec3::Zero();
    int dims = 2;
    NavigationGoal() = default;
    NavigationGoal(double x, double y) : p(x, y, 0.0), dims(2) {}
    NavigationGoal(double x, double y, double z) : p(x, y, z), dims(3) {}
    double x() const { return p.x(); }
    double y() const { return p.y(); }
    double z() const { return p.z(); }
};

struct NavigationStart {
    int goal = 0;  // index into the goals
    Vec3 start{0, 0, 0};
    bool success = false;
    double path_m = 0, shortest_m = 0, time_s = 0;
    std::vector<Vec3> path;  // positions after each move, from the start (z = 0 on the floor)
};

struct NavigationRun {
    double learn_s = 0;                        // simulated learning time
    double coverage = 0;                       // reached
    std::vector<int> visits;                   // per goal
    std::vector<int> goal_cells;               // per goal, -1 if never visited (the first scale's)
    std::vector<std::vector<double>> rewards;  // per goal, the reward cell's weights after replay (the first scale's)
    std::vector<NavigationStart> starts;
    std::vector<Vec3> learn_path;  // positions of the learning walk (every 8th step)
    // Per goal, the reward read-out r at points of a grid over the free floor, the place cells settled there (none
    // for a flying run).
    struct MapPoint {
        Vec2 p;
        double reward;
    };
    std::vector<std::vector<MapPoint>> reward_maps;
};

struct NavigationSetup {
    ModelSpec model;
    std::vector<NavigationGoal> goals;
    NavigationParams nav;
    AdjacencyParams adjacency;  // a flying run has the 20 flying HD cells (n_hd is the floor's)
    RewardParams reward;
    RobotParams robot;    // the agent on the floor
    FlightParams flight;  // the flying agent
    int dims() const { return goals.empty() ? 2 : goals.front().dims; }
};

// "goal 2 (1, 2)" or "goal 2 (1, 2, 3)": how messages name goal i.
std::string goal_text(std::size_t i, const NavigationGoal& g);

// InputError naming each goal outside the walkable floor (in 3-D: the flight volume), where the body does not fit,
// or that cannot be reached from the part of the floor (the flight volume) the learning walk roams; a goal whose
// dimension differs from the first's, or that the world has no room for (x, y in a flight-only world, x, y, z in
// a world without a flight volume); and for no goals.
void check_goals(const World& world, const NavigationSetup& setup);

// InputError if `model` is a preset for the other way of moving (a ground model with goals in 3-D, a flying one on
// the floor), as a trial refuses it.
void check_model(const ModelSpec& model, const NavigationSetup& setup);

// ParamError naming reward.scale_lambdas if the model has more scales of place cells than λs are given for.
void check_scales(const ModelSpec& model, const RewardParams& reward);

// One learning run and its exploitation. `progress` (if set) is told of each finished start.
NavigationRun navigate(const World& world, const NavigationSetup& setup, std::uint64_t seed,
                       const std::function<void(const NavigationStart&)>& progress = {});

}  // namespace bvc3d

#pragma once
// Agent stage: where a navigating agent moves (SPEC §17, docs/navigation.md), on the floor or flying. Takes: a world,
// the goals and the navigation's parameters. Gives: what the goals need of the world (checks naming each goal), the
// learning walk's body, coverage cells, starts, the shortest path (the yardstick, agent/shortest_path.hpp; in 3-D
// agent/voxel_path.hpp) and the agent that goes where a DirectionPolicy says (goal_seeking_walk.hpp,
// goal_seeking_flight.hpp).
//
// The space is picked by the goals' dimension: x, y on the floor (the paper's robot, its random walk, n_hd directions
// of the heading, the floor's 0.1 m grid) or x, y, z flying (SPEC §12's body and walk, the 20 directions of the
// flying HD cells, voxels). Nothing above this asks which one it has.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bvc3d/agent/flying_walk.hpp"
#include "bvc3d/agent/goal_seeking_walk.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/core/params.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

// How a start is posed and scored: bvc3d's (starts uniform on the goal's part of the floor, one stream per learning
// run and goal for the starts and the choices; the shortest path of agent/shortest_path.hpp) or the authors' (SPEC
// §17.3: starts as theirs, the same for every learning run; their optimal path, agent/authors_grid.hpp).
enum class NavigationProtocol { bvc3d, authors };

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
    NavigationProtocol protocol = NavigationProtocol::bvc3d;
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

// "goal 2 (1, 2)" or "goal 2 (1, 2, 3)": how messages, files and Python name goal i (counted from 1).
std::string goal_text(std::size_t i, const NavigationGoal& g);

// What a space is made of: the goals, the navigation's parameters, the bodies and the floor's number of directions.
struct NavigationSpaceSpec {
    std::vector<NavigationGoal> goals;
    NavigationParams nav;
    RobotParams robot;    // the agent on the floor
    FlightParams flight;  // the flying agent
    int n_hd = 8;         // directions on the floor (the adjacency's HD cells); flying: the 20 of the icosahedron
    int dims() const { return goals.empty() ? 2 : goals.front().dims; }
    // InputError for no goals, goals of mixed dimension, or a dimension no space has.
    void check_goals_shape() const;
};

class NavigationSpace {
public:
    virtual ~NavigationSpace() = default;
    // InputError naming goal i if it is outside, in geometry, or cannot be reached from where the walk roams.
    virtual void check_goal(std::size_t i, const NavigationGoal& g) const = 0;
    // The directions the agent chooses among (its HD cells').
    virtual int n_dir() const = 0;
    // Distance to a goal (in the plane on the floor).
    virtual double distance(const Vec3& a, const Vec3& b) const = 0;
    // Coverage: the cells counted (in the part the walk roams), and the index of p's cell if it is one of them.
    virtual std::size_t coverage_cells() const = 0;
    virtual std::size_t coverage_size() const = 0;
    virtual std::optional<std::size_t> coverage_cell(const Vec3& p) const = 0;
    // A random start at least `min_distance` from goal g, in its part of the space (under protocol authors, as SPEC
    // §17.3 draws it); then the pose there.
    virtual Vec3 draw_start(Rng& rng, std::size_t g, const NavigationGoal& goal, double min_distance) const = 0;
    virtual Pose start_pose(const Vec3& p, Rng& rng) const = 0;
    // The yardstick: the shortest path from `from` to the goal `to` (protocol authors: their optimal path to the
    // goal's disc of the success radius).
    virtual double shortest(const Vec3& from, const Vec3& to) const = 0;
    // The distance to walk from `from` to `to` round the geometry (bvc3d's shortest path, whatever the protocol):
    // how far a failed start still was from its goal.
    virtual double geodesic(const Vec3& from, const Vec3& to) const = 0;
    // The geometry the agent meets, as segments of the floor plane (the walls a figure draws); none in flight.
    virtual std::vector<std::array<Vec2, 2>> walls() const = 0;
    virtual std::unique_ptr<GoalSeeker> seeker(DirectionPolicy& policy, const Pose& start) const = 0;
    // Points of the floor for the reward maps (none in flight).
    virtual std::vector<Vec2> map_points(double cell) const = 0;
};

// The space of the spec's goals, after checking their shape and that the world has room for them (InputError naming
// the first goal and what the world lacks). The space keeps `spec` by reference.
std::unique_ptr<NavigationSpace> make_navigation_space(const WorldDescription& world, const NavigationSpaceSpec& spec);
// The random walk of the spec's space (the robot's, or the flying agent's), which the learning walk follows.
std::shared_ptr<const AgentSpec> navigation_walk(const NavigationSpaceSpec& spec);
// The number of directions of the spec's space, without a world.
int navigation_directions(const NavigationSpaceSpec& spec);

}  // namespace bvc3d

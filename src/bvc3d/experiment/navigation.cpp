#include "bvc3d/experiment/navigation.hpp"

#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "bvc3d/agent/body_collider.hpp"
#include "bvc3d/agent/free_space_grid.hpp"
#include "bvc3d/agent/goal_seeking_flight.hpp"
#include "bvc3d/agent/goal_seeking_walk.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/agent/shortest_path.hpp"
#include "bvc3d/agent/sphere_collider.hpp"
#include "bvc3d/agent/voxel_path.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/experiment/model_network.hpp"
#include "bvc3d/population/head_direction_cells.hpp"

namespace bvc3d {

const params::Table<NavigationParams>& NavigationParams::table() {
    using namespace params;
    using P = NavigationParams;
    static const Table<P> t(
        "navigation",
        {real("coverage", &P::coverage, closed(0, 1), "learning ends once this fraction of free cells is visited"),
         real("coverage_cell", &P::coverage_cell, closed(0.05, 100), "m, cells (voxels in 3-D) counted for coverage"),
         integer("goal_visits", &P::goal_visits, closed(0, 1000000),
                 "learning ends only once each goal has also been entered this often"),
         real("goal_radius", &P::goal_radius, closed(0.01, 100),
              "m, a goal's radius while learning (3-D distance in flight)"),
         real("max_learn_hours", &P::max_learn_hours, open_closed(0, max_agent_hours),
              "h, learning ends after this long at the latest"),
         integer("starts", &P::starts, closed(1, 1000000), "starts per goal"),
         real("min_start_distance", &P::min_start_distance, closed(0, 1e4), "m, a start's least distance to goal"),
         real("success_radius", &P::success_radius, closed(0.01, 100), "m, reached when this close to the goal"),
         real("max_path_ratio", &P::max_path_ratio, above(1), "fail when the path reaches this × the shortest"),
         real("max_hours", &P::max_hours, open_closed(0, max_agent_hours), "fail after this much time per start"),
         real("step", &P::step, closed(0.01, 10), "m per decision"),
         real("clearance", &P::clearance, closed(0, 100), "m of free travel a direction needs"),
         integer("settle_steps", &P::settle_steps, closed(0, 1000), "place-cell steps at a start before moving"),
         real("path_cell", &P::path_cell, closed(0.01, 10), "m, the shortest path's grid (voxels in 3-D)"),
         real("path_inflate", &P::path_inflate, closed(0, 100),
              "m, obstacles (in 3-D all geometry) inflated for the shortest path"),
         real("reward_map_cell", &P::reward_map_cell, closed(0, 100), "m between reward-map points; 0: no map")});
    return t;
}

std::string goal_text(std::size_t i, const NavigationGoal& g) {
    return "goal " + std::to_string(i + 1) + " (" + format_number(g.x()) + ", " + format_number(g.y()) +
           (g.dims == 3 ? ", " + format_number(g.z()) : std::string()) + ")";
}

namespace {

// The label of the part of the floor p lies in (-1 if none), on cells where the body fits.
int part_of(const FreeSpaceGrid& grid, const std::vector<int>& parts, const Vec2& p) {
    const auto c = grid.cell_of(p);
    return c ? parts[grid.index(*c)] : -1;
}

// The largest part: the one the walk roams.
int largest_part(const std::vector<int>& parts, int count) {
    std::vector<std::size_t> n(std::size_t(std::max(count, 1)), 0);
    for (int l : parts)
        if (l >= 0) ++n[std::size_t(l)];
    return count > 0 ? static_cast<int>(std::max_element(n.begin(), n.end()) - n.begin()) : -1;
}

Vec2 xy(const Vec3& p) { return {p.x(), p.y()}; }

// Where the agent moves (the seam between the loop and the body): what the learning walk is, what its HD cells
// read, what coverage counts, where starts may be, the shortest path, and the agent that goes where the policy says.
class NavigationSpace {
public:
    virtual ~NavigationSpace() = default;
    // InputError naming goal i if it is outside, in geometry, or cannot be reached.
    virtual void check_goal(std::size_t i, const NavigationGoal& g) const = 0;
    // HD cells: their number and their rates at a learning step (the steps come in order).
    virtual int n_dir() const = 0;
    virtual std::vector<double> learning_hd(const ModelStep& step) = 0;
    // Distance to a goal (in the plane on the floor).
    virtual double distance(const Vec3& a, const Vec3& b) const = 0;
    // Coverage: the cells counted (in the part the walk roams), and the index of p's cell if it is one of them.
    virtual std::size_t coverage_cells() const = 0;
    virtual std::size_t coverage_size() const = 0;
    virtual std::optional<std::size_t> coverage_cell(const Vec3& p) const = 0;
    // A random start at least `min_distance` from goal g, in its part of the space; then the pose there.
    virtual Vec3 draw_start(Rng& rng, std::size_t g, const NavigationGoal& goal, double min_distance) const = 0;
    virtual Pose start_pose(const Vec3& p, Rng& rng) const = 0;
    virtual double shortest(const Vec3& from, const Vec3& to) const = 0;
    virtual std::unique_ptr<GoalSeeker> seeker(DirectionPolicy& policy, const Pose& start) const = 0;
    // Points of the floor for the reward maps (none in flight).
    virtual std::vector<Vec2> map_points(double cell) const = 0;
};

// On the floor: the paper's robot (SPEC §4 and §17).
class FloorSpace : public NavigationSpace {
public:
    FloorSpace(const World& world, const NavigationSetup& s)
        : s_(s),
          body_(std::make_shared<const BodyCollider>(world.description(), s.robot.radius, s.robot.height)),
          path_grid_(*body_, s.nav.path_cell),
          cover_grid_(*body_, s.nav.coverage_cell) {
        int n = 0;
        parts_ = path_grid_.parts(s.robot.radius, n);
        main_ = largest_part(parts_, n);
        cover_parts_ = cover_grid_.parts(s.robot.radius, n);
        cover_main_ = largest_part(cover_parts_, n);
        for (int l : cover_parts_) cover_free_ += l == cover_main_;
    }
    void check_goal(std::size_t i, const NavigationGoal& goal) const override {
        const Vec2 g = xy(goal.p);
        if (!std::isfinite(g.x()) || !std::isfinite(g.y()) || !body_->walkable().contains(g))
            throw InputError("navigation: " + goal_text(i, goal) + " lies outside the world's walkable floor");
        if (body_->clearance(g) < 0)
            throw InputError("navigation: " + goal_text(i, goal) +
                             " lies in or against a wall (the robot's body, radius " + format_number(s_.robot.radius) +
                             " m, does not fit there)");
        const auto c = nearest_usable_cell(path_grid_, g, s_.robot.radius);
        if (!c || parts_[path_grid_.index(*c)] != main_)
            throw InputError("navigation: " + goal_text(i, goal) +
                             " cannot be reached from the floor the robot walks (a closed-off pocket)");
    }
    int n_dir() const override { return s_.adjacency.n_hd; }
    std::vector<double> learning_hd(const ModelStep& step) override {
        return hd_rates(step.pose.heading, s_.adjacency.n_hd);
    }
    double distance(const Vec3& a, const Vec3& b) const override { return (xy(a) - xy(b)).norm(); }
    std::size_t coverage_cells() const override { return cover_free_; }
    std::size_t coverage_size() const override { return cover_grid_.size(); }
    std::optional<std::size_t> coverage_cell(const Vec3& p) const override {
        const auto c = cover_grid_.cell_of(xy(p));
        if (!c || cover_parts_[cover_grid_.index(*c)] != cover_main_) return std::nullopt;
        return cover_grid_.index(*c);
    }
    Vec3 draw_start(Rng& rng, std::size_t g, const NavigationGoal& goal, double min_distance) const override {
        const Vec2 at = xy(goal.p);
        const int goal_part = parts_[path_grid_.index(*nearest_usable_cell(path_grid_, at, s_.robot.radius))];
        const auto bounds = body_->walkable().bounds();
        for (int tries = 0; tries <= 100000; ++tries) {
            const Vec2 p(rng.uniform(bounds.min().x(), bounds.max().x()),
                         rng.uniform(bounds.min().y(), bounds.max().y()));
            if ((p - at).norm() >= min_distance && body_->walkable().contains(p) && body_->clearance(p) >= 0.05 &&
                part_of(path_grid_, parts_, p) == goal_part)
                return {p.x(), p.y(), 0.0};
        }
        throw InputError("navigation: no start at least " + format_number(min_distance) + " m from " +
                         goal_text(g, goal) + " on its floor");
    }
    Pose start_pose(const Vec3& p, Rng& rng) const override {
        return Pose::on_floor(p.x(), p.y(), rng.uniform(-pi, pi));
    }
    double shortest(const Vec3& from, const Vec3& to) const override {
        return shortest_path(path_grid_, xy(from), xy(to), s_.nav.path_inflate).length;
    }
    std::unique_ptr<GoalSeeker> seeker(DirectionPolicy& policy, const Pose& start) const override {
        return std::make_unique<GoalSeekingWalk>(
            body_, s_.robot, GoalSeekingParams{s_.adjacency.n_hd, s_.nav.step, s_.nav.clearance}, policy, start);
    }
    std::vector<Vec2> map_points(double cell) const override {
        std::vector<Vec2> out;
        const auto bounds = body_->walkable().bounds();
        if (cell > 0)
            for (double y = bounds.min().y() + cell / 2; y < bounds.max().y(); y += cell)
                for (double x = bounds.min().x() + cell / 2; x < bounds.max().x(); x += cell) {
                    const Vec2 q(x, y);
                    if (body_->walkable().contains(q) && body_->clearance(q) >= 0) out.push_back(q);
                }
        return out;
    }

private:
    const NavigationSetup& s_;
    std::shared_ptr<const BodyCollider> body_;
    FreeSpaceGrid path_grid_, cover_grid_;
    std::vector<int> parts_, cover_parts_;
    int main_ = -1, cover_main_ = -1;
    std::size_t cover_free_ = 0;
};

// Flying (SPEC §12 and §17 in 3-D): the sphere, its walk, the 20 flying HD cells, voxels.
class FlightSpace : public NavigationSpace {
public:
    FlightSpace(const World& world, const NavigationSetup& s)
        : s_(s),
          body_(std::make_shared<const SphereCollider>(world.description(), s.flight.radius)),
          occupancy_(voxel_occupancy(*body_, s.nav.path_cell, s.nav.path_inflate)) {
        int n = 0;
        parts_ = voxel_parts(occupancy_, n);
        main_ = largest_part(parts_, n);
        // Coverage: voxels of coverage_cell m over the box of centre positions, counted where the body can start
        // at the voxel's centre (free, and in the free space the walk roams).
        const auto& box = body_->center_box();
        cover_.cell = s.nav.coverage_cell;
        cover_.origin = box.min();
        cover_.nx = std::max(1, int(std::ceil(box.sizes().x() / cover_.cell)));
        cover_.ny = std::max(1, int(std::ceil(box.sizes().y() / cover_.cell)));
        cover_.nz = std::max(1, int(std::ceil(box.sizes().z() / cover_.cell)));
        cover_.free.assign(std::size_t(cover_.nx) * cover_.ny * cover_.nz, 0);
        for (std::size_t i = 0; i < cover_.size(); ++i)
            cover_free_ += cover_.free[i] = body_->can_start_at(cover_.center(cover_.voxel_at(i)));
    }
    void check_goal(std::size_t i, const NavigationGoal& goal) const override {
        const Vec3& g = goal.p;
        const auto& v = body_->volume();
        if (!g.allFinite() || !v.region.contains(xy(g)) || g.z() < v.z_min || g.z() > v.z_max)
            throw InputError("navigation: " + goal_text(i, goal) + " lies outside the world's flight volume");
        if (!body_->is_free(g))
            throw InputError("navigation: " + goal_text(i, goal) +
                             " lies in or against geometry or the flight volume's bounds (the flying body, radius " +
                             format_number(s_.flight.radius) + " m, does not fit there)");
        if (!body_->can_start_at(g) || part_of_voxel(g) != main_)
            throw InputError(
                "navigation: " + goal_text(i, goal) +
                " cannot be reached from the space the agent flies (inside a solid, or a closed-off pocket)");
    }
    int n_dir() const override { return 20; }
    std::vector<double> learning_hd(const ModelStep& step) override {
        // SPEC §16: the direction of motion, the displacement since the last step (the head stays level); at the
        // first step, or without motion, the pose's own.
        const Vec3 p = step.pose.position();
        Vec3 w = has_last_ ? Vec3(p - last_) : Vec3::Zero();
        if (!(w.norm() > 0)) w = hd::direction(step.pose.heading, step.pose.pitch);
        last_ = p, has_last_ = true;
        std::vector<double> out(20);
        hd::spherical_rates(w, out);
        return out;
    }
    double distance(const Vec3& a, const Vec3& b) const override { return (a - b).norm(); }
    std::size_t coverage_cells() const override { return cover_free_; }
    std::size_t coverage_size() const override { return cover_.size(); }
    std::optional<std::size_t> coverage_cell(const Vec3& p) const override {
        const auto v = cover_.voxel_of(p);
        if (!v || !cover_.usable((*v)[0], (*v)[1], (*v)[2])) return std::nullopt;
        return cover_.index((*v)[0], (*v)[1], (*v)[2]);
    }
    Vec3 draw_start(Rng& rng, std::size_t g, const NavigationGoal& goal, double min_distance) const override {
        const int goal_part = part_of_voxel(goal.p);
        const auto& box = body_->center_box();
        for (int tries = 0; tries <= 100000; ++tries) {
            const Vec3 p(rng.uniform(box.min().x(), box.max().x()), rng.uniform(box.min().y(), box.max().y()),
                         rng.uniform(box.min().z(), box.max().z()));
            if ((p - goal.p).norm() >= min_distance && body_->is_free(p) && body_->clearance(p) >= 0.05 &&
                body_->can_start_at(p) && part_of_voxel(p) == goal_part)
                return p;
        }
        throw InputError("navigation: no start at least " + format_number(min_distance) + " m from " +
                         goal_text(g, goal) + " in its flight volume");
    }
    Pose start_pose(const Vec3& p, Rng& rng) const override {
        return Pose{p.x(), p.y(), p.z(), rng.uniform(-pi, pi), 0.0, 0.0};
    }
    double shortest(const Vec3& from, const Vec3& to) const override {
        return voxel_path_between(occupancy_, from, to).value_or(0.0);
    }
    std::unique_ptr<GoalSeeker> seeker(DirectionPolicy& policy, const Pose& start) const override {
        const auto& faces = hd::icosahedron_faces();
        return std::make_unique<FlyingGoalSeeker>(
            body_, s_.flight, FlyingSeekingParams{{faces.begin(), faces.end()}, s_.nav.step, s_.nav.clearance}, policy,
            start);
    }
    std::vector<Vec2> map_points(double) const override { return {}; }

private:
    int part_of_voxel(const Vec3& p) const {
        const auto v = nearest_free_voxel(occupancy_, p);
        return v ? parts_[occupancy_.index((*v)[0], (*v)[1], (*v)[2])] : -1;
    }
    const NavigationSetup& s_;
    std::shared_ptr<const SphereCollider> body_;
    VoxelGrid3 occupancy_, cover_;
    std::vector<int> parts_;
    int main_ = -1;
    std::size_t cover_free_ = 0;
    Vec3 last_ = Vec3::Zero();
    bool has_last_ = false;
};

// The spaces, by the goals' dimension: what a goal of that dimension needs of the world, the learning walk's agent
// (also what the model must suit) and the space.
struct SpaceKind {
    int dims;
    bool (*fits)(const WorldDescription& world);
    const char* needs;  // what the world lacks when it does not fit
    std::shared_ptr<const AgentSpec> (*agent)(const NavigationSetup& setup);
    std::unique_ptr<NavigationSpace> (*make)(const World& world, const NavigationSetup& setup);
};

const std::vector<SpaceKind>& space_kinds() {
    static const std::vector<SpaceKind> kinds{
        {2, [](const WorldDescription& w) { return !w.walkable.points.empty(); },
         "has no walkable floor (a flight-only world: give goals as x,y,z)",
         [](const NavigationSetup& s) -> std::shared_ptr<const AgentSpec> {
             return std::make_shared<RandomWalkSpec>(s.robot);
         },
         [](const World& w, const NavigationSetup& s) -> std::unique_ptr<NavigationSpace> {
             return std::make_unique<FloorSpace>(w, s);
         }},
        {3, [](const WorldDescription& w) { return w.flight.has_value(); },
         "has no flight volume (a ground world: give goals as x,y)",
         [](const NavigationSetup& s) -> std::shared_ptr<const AgentSpec> {
             return std::make_shared<FlightSpec>(s.flight);
         },
         [](const World& w, const NavigationSetup& s) -> std::unique_ptr<NavigationSpace> {
             return std::make_unique<FlightSpace>(w, s);
         }},
    };
    return kinds;
}

const SpaceKind& space_kind(int dims) {
    for (const auto& k : space_kinds())
        if (k.dims == dims) return k;
    throw InputError("navigation: goals have 2 or 3 coordinates, not " + std::to_string(dims));
}

// The space of the setup's goals, after checking that they all have one dimension and the world has room for them.
std::unique_ptr<NavigationSpace> make_space(const World& world, const NavigationSetup& s) {
    if (s.goals.empty()) throw InputError("navigation: no goals given");
    for (std::size_t i = 1; i < s.goals.size(); ++i)
        if (s.goals[i].dims != s.goals.front().dims)
            throw InputError("navigation: " + goal_text(i, s.goals[i]) + " has " + std::to_string(s.goals[i].dims) +
                             " coordinates but goal 1 has " + std::to_string(s.goals.front().dims) +
                             " (all goals on the floor, x,y, or all in 3-D, x,y,z)");
    const SpaceKind& kind = space_kind(s.dims());
    if (!kind.fits(world.description()))
        throw InputError("navigation: " + goal_text(0, s.goals.front()) + ": world '" + world.name() + "' " +
                         kind.needs);
    return kind.make(world, s);
}

// The model's senses: its populations (model_network.hpp) stepped one model step at a time, and the rates of its
// scales of place cells (ModelSpec::place_scales: the paper's model has one, a multiscale model three).
class Senses {
public:
    Senses(const World& world, const ModelSpec& model, std::shared_ptr<const AgentSpec> agent, std::uint64_t seed)
        : net_(&world, {trial_of(model, std::move(agent), seed)}, {}, false, 1) {
        const auto& nodes = net_.nodes.front();
        for (const std::string& name : model.place_scales()) {
            std::size_t node = nodes.place;
            for (std::size_t k = 0; k < model.populations.size(); ++k)
                if (model.populations[k].name == name) node = nodes.others[k];
            scales_.push_back(node);
        }
        rates_.resize(scales_.size());
    }
    std::size_t n_scales() const { return scales_.size(); }
    int n_place(std::size_t s) const { return static_cast<int>(net_.network.node(scales_[s]).population->size()); }
    // One model step at `pose`; each scale's place-cell rates after it.
    const std::vector<std::vector<double>>& step(const Pose& pose, bool learn, bool bumped = false, double t = 0.0) {
        net_.network.step(ModelStep{t, pose, bumped, std::nullopt}, index_++, learn, false);
        for (std::size_t s = 0; s < scales_.size(); ++s) {
            const auto v = net_.network.latest(scales_[s]);
            rates_[s].assign(v.begin(), v.end());
        }
        return rates_;
    }
    const std::vector<std::vector<double>>& rates() const { return rates_; }
    // Every population back to rest (a new start), what it learned kept.
    void reset() {
        for (std::size_t i = 0; i < net_.network.size(); ++i) net_.network.node(i).population->reset_activity();
    }

private:
    static TrialConfig trial_of(const ModelSpec& model, std::shared_ptr<const AgentSpec> agent, std::uint64_t seed) {
        TrialConfig t;
        t.model = model;
        t.set_agent(std::move(agent));
        t.seed = seed;
        return t;
    }
    ModelNetwork net_;
    std::vector<std::size_t> scales_;  // the nodes of the place-cell scales
    std::int64_t index_ = 0;
    std::vector<std::vector<double>> rates_;
};

// What one scale gives the choice: its frozen adjacency, its parameters and, per goal, its reward cell's weights.
struct ScaleMemory {
    SparseAdjacency adjacency;
    std::optional<PackedAdjacency> packed;  // what the rollouts read, if `adjacency.rollout_weights` is float16
    RewardParams reward;
    std::vector<std::vector<double>> rewards;  // per goal
    // Each direction's return toward goal g from the scale's rates v, through the copy the rollouts read.
    std::vector<double> returns(std::size_t g, std::span<const double> v, std::span<const char> offered) const {
        return packed ? direction_returns(*packed, rewards[g], v, reward, offered)
                      : direction_returns(adjacency, rewards[g], v, reward, offered);
    }
};

// SPEC §17's choice: per scale softmax(β·R) over the offered directions, the scales combined (combine_scales),
// sampled.
class RewardPolicy : public DirectionPolicy {
public:
    RewardPolicy(const std::vector<ScaleMemory>& scales, std::size_t goal, const Senses& senses, const RewardParams& p,
                 Rng& rng)
        : scales_(scales), goal_(goal), senses_(senses), p_(p), rng_(rng) {}
    int choose(const Pose&, std::span<const char> allowed) override {
        std::vector<std::vector<double>> returns;
        for (std::size_t s = 0; s < scales_.size(); ++s)
            returns.push_back(scales_[s].returns(goal_, senses_.rates()[s], allowed));
        const auto prob = combine_scales(returns, {allowed.begin(), allowed.end()}, p_, scores_);
        const double u = rng_.uniform();
        double sum = 0;
        int last = -1;
        for (std::size_t d = 0; d < prob.size(); ++d) {
            if (!allowed[d]) continue;
            last = static_cast<int>(d);
            if (u < (sum += prob[d])) return last;
        }
        return last;
    }

private:
    const std::vector<ScaleMemory>& scales_;
    std::size_t goal_;
    const Senses& senses_;
    RewardParams p_;
    Rng& rng_;
    std::vector<double> scores_;  // each scale's smoothed score over this start's decisions
};

}  // namespace

void check_goals(const World& world, const NavigationSetup& s) {
    const auto space = make_space(world, s);
    for (std::size_t i = 0; i < s.goals.size(); ++i) space->check_goal(i, s.goals[i]);
}

void check_model(const ModelSpec& model, const NavigationSetup& s) {
    TrialConfig t;
    t.model = model;
    t.set_agent(space_kind(s.dims()).agent(s));
    t.validate();
}

void check_scales(const ModelSpec& model, const RewardParams& reward) {
    const std::size_t n = model.place_scales().size(), given = reward.scale_lambdas.size() + 1;
    if (n > given)
        RewardParams::table().fail("scale_lambdas", "gives λ for " + std::to_string(given) +
                                                        " scales (with lambda), but '" + model.name + "' has " +
                                                        std::to_string(n) + " scales of place cells");
}

NavigationRun navigate(const World& world, const NavigationSetup& s, std::uint64_t seed,
                       const std::function<void(const NavigationStart&)>& progress) {
    s.nav.validate();
    s.reward.validate();
    s.model.validate();
    const auto space = make_space(world, s);
    for (std::size_t i = 0; i < s.goals.size(); ++i) space->check_goal(i, s.goals[i]);
    check_scales(s.model, s.reward);
    check_model(s.model, s);
    const NavigationParams& nav = s.nav;
    const auto agent = space_kind(s.dims()).agent(s);
    Senses senses(world, s.model, agent, seed);
    const std::size_t n_scales = senses.n_scales();
    AdjacencyParams adjacency_params = s.adjacency;
    adjacency_params.n_hd = space->n_dir();
    std::vector<HdAdjacency> adjacency;  // per scale, learned
    for (std::size_t k = 0; k < n_scales; ++k) adjacency.emplace_back(senses.n_place(k), adjacency_params);
    NavigationRun run;
    const std::size_t n_goals = s.goals.size();
    run.visits.assign(n_goals, 0);
    // Per scale and goal: the reward cell (the most active inside the goal's radius) and its rate.
    std::vector<std::vector<int>> goal_cells(n_scales, std::vector<int>(n_goals, -1));
    std::vector<std::vector<double>> best(n_scales, std::vector<double>(n_goals, 0.0));

    // Learning.
    const std::size_t free_cells = space->coverage_cells();
    std::size_t covered = 0;
    std::vector<char> visited(space->coverage_size(), 0);
    std::vector<char> inside(n_goals, 0);
    const auto walk = agent->make(&world, seed);
    const double learn_end = nav.max_learn_hours * 3600;
    for (std::int64_t k = 0;; ++k) {
        const auto step = walk->next(learn_end);
        if (!step) break;
        const Vec3 p = step->pose.position();
        const auto& rates = senses.step(step->pose, true, step->bumped, step->t);
        const auto hd = space->learning_hd(*step);
        for (std::size_t sc = 0; sc < n_scales; ++sc) adjacency[sc].learn(rates[sc], hd, step->bumped);
        if (k % 8 == 0) run.learn_path.push_back(p);
        if (const auto c = space->coverage_cell(p); c && !visited[*c]) {
            visited[*c] = 1;
            ++covered;
        }
        bool goals_done = true;
        for (std::size_t g = 0; g < n_goals; ++g) {
            const bool in = space->distance(p, s.goals[g].p) <= nav.goal_radius;
            if (in && !inside[g]) ++run.visits[g];
            inside[g] = in;
            if (in)
                for (std::size_t sc = 0; sc < n_scales; ++sc)
                    for (std::size_t i = 0; i < rates[sc].size(); ++i)
                        if (rates[sc][i] > best[sc][g])
                            best[sc][g] = rates[sc][i], goal_cells[sc][g] = static_cast<int>(i);
            goals_done = goals_done && run.visits[g] >= nav.goal_visits;
        }
        run.learn_s = step->t;
        run.coverage = free_cells ? double(covered) / double(free_cells) : 1.0;
        if (goals_done && run.coverage >= nav.coverage) break;
    }

    // Exploitation, per scale on the learned adjacency's sparse copy, after replay from each goal's reward cell.
    std::vector<ScaleMemory> memory;
    for (std::size_t k = 0; k < n_scales; ++k) {
        memory.push_back({SparseAdjacency(adjacency[k]), std::nullopt, s.reward.for_scale(k), {}});
        if (adjacency_params.rollout_weights == RolloutWeights::float16)
            memory.back().packed.emplace(adjacency[k], adjacency_params.prune);
        adjacency[k] = HdAdjacency(1, adjacency_params);  // its dense matrices are not needed any more
        for (std::size_t g = 0; g < n_goals; ++g)
            memory[k].rewards.push_back(goal_cells[k][g] >= 0
                                            ? replay(memory[k].adjacency, goal_cells[k][g], memory[k].reward)
                                            : std::vector<double>(std::size_t(senses.n_place(k)), 0.0));
    }
    // What a run reports: the first scale's (the model's own place cells).
    run.goal_cells = goal_cells.front();
    run.rewards = memory.front().rewards;
    const auto map_points = space->map_points(nav.reward_map_cell);
    for (std::size_t g = 0; g < n_goals; ++g) {
        const NavigationGoal& goal = s.goals[g];
        const auto& w = run.rewards[g];
        run.reward_maps.emplace_back();
        for (const Vec2& q : map_points) {
            senses.reset();
            for (int k = 0; k < std::max(1, nav.settle_steps); ++k)
                senses.step(Pose::on_floor(q.x(), q.y(), 0.0), false);
            run.reward_maps.back().push_back({q, reward(w, senses.rates().front())});
        }
        Rng rng(hash_u64(seed, 0x6e617669676174ULL, g), Stream::walk);
        for (int i = 0; i < nav.starts; ++i) {
            NavigationStart out;
            out.goal = static_cast<int>(g);
            const Vec3 p = space->draw_start(rng, g, goal, nav.min_start_distance);
            out.start = p;
            out.shortest_m = space->shortest(p, goal.p);
            senses.reset();
            const Pose pose = space->start_pose(p, rng);
            for (int k = 0; k < std::max(1, nav.settle_steps); ++k) senses.step(pose, false);
            RewardPolicy policy(memory, g, senses, s.reward, rng);
            const auto agent_here = space->seeker(policy, pose);
            out.path.push_back(p);
            while (true) {
                if (space->distance(agent_here->pose().position(), goal.p) <= nav.success_radius) {
                    out.success = true;
                    break;
                }
                if (agent_here->travelled() >= nav.max_path_ratio * out.shortest_m) break;
                const auto step = agent_here->next(nav.max_hours * 3600);
                if (!step) break;
                senses.step(step->pose, false, step->bumped, step->t);
                out.path.push_back(step->pose.position());
            }
            out.path_m = agent_here->travelled();
            out.time_s = agent_here->time();
            if (progress) progress(out);
            run.starts.push_back(std::move(out));
        }
    }
    return run;
}

}  // namespace bvc3d

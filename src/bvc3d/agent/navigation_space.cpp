#include "bvc3d/agent/navigation_space.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "bvc3d/agent/authors_grid.hpp"
#include "bvc3d/agent/body_collider.hpp"
#include "bvc3d/agent/free_space_grid.hpp"
#include "bvc3d/agent/goal_seeking_flight.hpp"
#include "bvc3d/agent/shortest_path.hpp"
#include "bvc3d/agent/sphere_collider.hpp"
#include "bvc3d/agent/voxel_path.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/icosahedron.hpp"
#include "bvc3d/core/uniform_point.hpp"

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
         real("reward_map_cell", &P::reward_map_cell, closed(0, 100), "m between reward-map points; 0: no map"),
         choice("protocol", &P::protocol,
                {{NavigationProtocol::bvc3d, "bvc3d"}, {NavigationProtocol::authors, "authors"}},
                "starts and yardstick: bvc3d's, or the authors' (SPEC §17.3: their starts, the same for every "
                "learning run, and their optimal path to the goal's disc; on the floor only)")
             .quiet_at_default()});
    return t;
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

// On the floor: the paper's robot (SPEC §4 and §17).
class FloorSpace : public NavigationSpace {
public:
    FloorSpace(const WorldDescription& world, const NavigationSpaceSpec& s)
        : s_(s),
          body_(std::make_shared<const BodyCollider>(world, s.robot.radius, s.robot.height)),
          path_grid_(*body_, s.nav.path_cell),
          cover_grid_(*body_, s.nav.coverage_cell) {
        int n = 0;
        parts_ = path_grid_.parts(s.robot.radius, n);
        main_ = largest_part(parts_, n);
        cover_parts_ = cover_grid_.parts(s.robot.radius, n);
        cover_main_ = largest_part(cover_parts_, n);
        for (int l : cover_parts_) cover_free_ += l == cover_main_;
        if (s.nav.protocol == NavigationProtocol::authors)
            authors_.emplace(*body_, s.nav.path_cell, s.nav.path_inflate);
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
    int n_dir() const override { return s_.n_hd; }
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
        if (authors_) {
            const Vec2 p =
                authors_->draw_start(rng, *body_, at, min_distance, s_.nav.path_inflate, s_.nav.success_radius);
            return {p.x(), p.y(), 0.0};
        }
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
        if (authors_) {
            const auto path = authors_->shortest(xy(from), xy(to), s_.nav.success_radius);
            return path ? path->length : 0.0;
        }
        return geodesic(from, to);
    }
    double geodesic(const Vec3& from, const Vec3& to) const override {
        return shortest_path(path_grid_, xy(from), xy(to), s_.nav.path_inflate).length;
    }
    std::vector<std::array<Vec2, 2>> walls() const override {
        std::vector<std::array<Vec2, 2>> out;
        for (const Segment2& seg : body_->segments()) out.push_back({seg.a, seg.b});
        return out;
    }
    std::unique_ptr<GoalSeeker> seeker(DirectionPolicy& policy, const Pose& start) const override {
        return std::make_unique<GoalSeekingWalk>(
            body_, s_.robot, GoalSeekingParams{s_.n_hd, s_.nav.step, s_.nav.clearance}, policy, start);
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
    const NavigationSpaceSpec& s_;
    std::shared_ptr<const BodyCollider> body_;
    FreeSpaceGrid path_grid_, cover_grid_;
    std::vector<int> parts_, cover_parts_;
    int main_ = -1, cover_main_ = -1;
    std::size_t cover_free_ = 0;
    std::optional<AuthorsGrid> authors_;  // protocol authors
};

// Flying (SPEC §12 and §17 in 3-D): the sphere, its walk, the 20 flying HD cells, voxels.
class FlightSpace : public NavigationSpace {
public:
    FlightSpace(const WorldDescription& world, const NavigationSpaceSpec& s)
        : s_(s),
          body_(std::make_shared<const SphereCollider>(world, s.flight.radius)),
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
            const Vec3 p = uniform_point(box, rng);
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
    double shortest(const Vec3& from, const Vec3& to) const override { return geodesic(from, to); }
    double geodesic(const Vec3& from, const Vec3& to) const override {
        return voxel_path_between(occupancy_, from, to).value_or(0.0);
    }
    std::unique_ptr<GoalSeeker> seeker(DirectionPolicy& policy, const Pose& start) const override {
        const auto& faces = icosahedron_faces();
        return std::make_unique<FlyingGoalSeeker>(
            body_, s_.flight, FlyingSeekingParams{{faces.begin(), faces.end()}, s_.nav.step, s_.nav.clearance}, policy,
            start);
    }
    std::vector<Vec2> map_points(double) const override { return {}; }
    std::vector<std::array<Vec2, 2>> walls() const override { return {}; }

private:
    int part_of_voxel(const Vec3& p) const {
        const auto v = nearest_free_voxel(occupancy_, p);
        return v ? parts_[occupancy_.index((*v)[0], (*v)[1], (*v)[2])] : -1;
    }
    const NavigationSpaceSpec& s_;
    std::shared_ptr<const SphereCollider> body_;
    VoxelGrid3 occupancy_, cover_;
    std::vector<int> parts_;
    int main_ = -1;
    std::size_t cover_free_ = 0;
};

// The spaces, by the goals' dimension: what a goal of that dimension needs of the world, the learning walk's body,
// the number of directions, and the space.
struct SpaceKind {
    int dims;
    bool (*fits)(const WorldDescription& world);
    const char* needs;  // what the world lacks when it does not fit
    std::shared_ptr<const AgentSpec> (*walk)(const NavigationSpaceSpec& spec);
    int (*directions)(const NavigationSpaceSpec& spec);
    std::unique_ptr<NavigationSpace> (*make)(const WorldDescription& world, const NavigationSpaceSpec& spec);
};

const std::vector<SpaceKind>& space_kinds() {
    static const std::vector<SpaceKind> kinds{
        {2, [](const WorldDescription& w) { return !w.walkable.points.empty(); },
         "has no walkable floor (a flight-only world: give goals as x,y,z)",
         [](const NavigationSpaceSpec& s) -> std::shared_ptr<const AgentSpec> {
             return std::make_shared<RandomWalkSpec>(s.robot);
         },
         [](const NavigationSpaceSpec& s) { return s.n_hd; },
         [](const WorldDescription& w, const NavigationSpaceSpec& s) -> std::unique_ptr<NavigationSpace> {
             return std::make_unique<FloorSpace>(w, s);
         }},
        {3, [](const WorldDescription& w) { return w.flight.has_value(); },
         "has no flight volume (a ground world: give goals as x,y)",
         [](const NavigationSpaceSpec& s) -> std::shared_ptr<const AgentSpec> {
             return std::make_shared<FlightSpec>(s.flight);
         },
         [](const NavigationSpaceSpec&) { return static_cast<int>(icosahedron_faces().size()); },
         [](const WorldDescription& w, const NavigationSpaceSpec& s) -> std::unique_ptr<NavigationSpace> {
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

}  // namespace

std::string goal_text(std::size_t i, const NavigationGoal& g) {
    return "goal " + std::to_string(i + 1) + " (" + format_number(g.x()) + ", " + format_number(g.y()) +
           (g.dims == 3 ? ", " + format_number(g.z()) : std::string()) + ")";
}

void NavigationSpaceSpec::check_goals_shape() const {
    if (goals.empty()) throw InputError("navigation: no goals given");
    for (std::size_t i = 1; i < goals.size(); ++i)
        if (goals[i].dims != goals.front().dims)
            throw InputError("navigation: " + goal_text(i, goals[i]) + " has " + std::to_string(goals[i].dims) +
                             " coordinates but goal 1 has " + std::to_string(goals.front().dims) +
                             " (all goals on the floor, x,y, or all in 3-D, x,y,z)");
    space_kind(dims());
}

std::unique_ptr<NavigationSpace> make_navigation_space(const WorldDescription& world, const NavigationSpaceSpec& s) {
    s.check_goals_shape();
    const SpaceKind& kind = space_kind(s.dims());
    if (!kind.fits(world))
        throw InputError("navigation: " + goal_text(0, s.goals.front()) + ": world '" + world.name + "' " + kind.needs);
    return kind.make(world, s);
}

std::shared_ptr<const AgentSpec> navigation_walk(const NavigationSpaceSpec& s) { return space_kind(s.dims()).walk(s); }

int navigation_directions(const NavigationSpaceSpec& s) { return space_kind(s.dims()).directions(s); }

}  // namespace bvc3d

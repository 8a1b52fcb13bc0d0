#include "bvc3d/experiment/navigation.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "bvc3d/agent/body_collider.hpp"
#include "bvc3d/agent/free_space_grid.hpp"
#include "bvc3d/agent/goal_seeking_walk.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/agent/shortest_path.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/experiment/model_network.hpp"

namespace bvc3d {

const params::Table<NavigationParams>& NavigationParams::table() {
    using namespace params;
    using P = NavigationParams;
    static const Table<P> t(
        "navigation",
        {real("coverage", &P::coverage, closed(0, 1), "learning ends once this fraction of free cells is visited"),
         real("coverage_cell", &P::coverage_cell, closed(0.05, 100), "m, cells counted for coverage"),
         integer("goal_visits", &P::goal_visits, closed(0, 1000000), "and each goal has been entered this often"),
         real("goal_radius", &P::goal_radius, closed(0.01, 100), "m, a goal's radius while learning"),
         real("max_learn_hours", &P::max_learn_hours, open_closed(0, max_agent_hours), "or after this much time"),
         integer("starts", &P::starts, closed(1, 1000000), "starts per goal"),
         real("min_start_distance", &P::min_start_distance, closed(0, 1e4), "m, a start's least distance to goal"),
         real("success_radius", &P::success_radius, closed(0.01, 100), "m, reached when this close to the goal"),
         real("max_path_ratio", &P::max_path_ratio, above(1), "fail when the path reaches this × the shortest"),
         real("max_hours", &P::max_hours, open_closed(0, max_agent_hours), "fail after this much time per start"),
         real("step", &P::step, closed(0.01, 10), "m per decision"),
         real("clearance", &P::clearance, closed(0, 100), "m of free travel a direction needs"),
         integer("settle_steps", &P::settle_steps, closed(0, 1000), "place-cell steps at a start before moving"),
         real("path_cell", &P::path_cell, closed(0.01, 10), "m, the shortest path's grid"),
         real("path_inflate", &P::path_inflate, closed(0, 100), "m, obstacles inflated for the shortest path"),
         real("reward_map_cell", &P::reward_map_cell, closed(0, 100), "m between reward-map points; 0: no map")});
    return t;
}

namespace {

std::string goal_text(std::size_t i, const Vec2& g) {
    return "goal " + std::to_string(i + 1) + " (" + format_number(g.x()) + ", " + format_number(g.y()) + ")";
}

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

// The model's senses: its populations (model_network.hpp) stepped one model step at a time, and the rates of its
// scales of place cells (ModelSpec::place_scales: the paper's model has one, a multiscale model three).
class Senses {
public:
    Senses(const World& world, const ModelSpec& model, std::uint64_t seed)
        : net_(&world, {trial_of(model, seed)}, {}, false, 1) {
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
    static TrialConfig trial_of(const ModelSpec& model, std::uint64_t seed) {
        TrialConfig t;
        t.model = model;
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
    RewardParams reward;
    std::vector<std::vector<double>> rewards;  // per goal
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
            returns.push_back(direction_returns(scales_[s].adjacency, scales_[s].rewards[goal_], senses_.rates()[s],
                                                scales_[s].reward));
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
    if (s.goals.empty()) throw InputError("navigation: no goals given");
    const BodyCollider body(world.description(), s.robot.radius, s.robot.height);
    const FreeSpaceGrid grid(body, s.nav.path_cell);
    int count = 0;
    const auto parts = grid.parts(s.robot.radius, count);
    const int main = largest_part(parts, count);
    for (std::size_t i = 0; i < s.goals.size(); ++i) {
        const Vec2& g = s.goals[i];
        if (!std::isfinite(g.x()) || !std::isfinite(g.y()) || !body.walkable().contains(g))
            throw InputError("navigation: " + goal_text(i, g) + " lies outside the world's walkable floor");
        if (body.clearance(g) < 0)
            throw InputError("navigation: " + goal_text(i, g) +
                             " lies in or against a wall (the robot's body, radius " + format_number(s.robot.radius) +
                             " m, does not fit there)");
        const auto c = nearest_usable_cell(grid, g, s.robot.radius);
        if (!c || parts[grid.index(*c)] != main)
            throw InputError("navigation: " + goal_text(i, g) +
                             " cannot be reached from the floor the robot walks (a closed-off pocket)");
    }
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
    check_goals(world, s);
    check_scales(s.model, s.reward);
    const NavigationParams& nav = s.nav;
    auto body = std::make_shared<const BodyCollider>(world.description(), s.robot.radius, s.robot.height);
    const FreeSpaceGrid path_grid(*body, nav.path_cell);
    const FreeSpaceGrid cover_grid(*body, nav.coverage_cell);
    Senses senses(world, s.model, seed);
    const std::size_t n_scales = senses.n_scales();
    std::vector<HdAdjacency> adjacency;  // per scale, learned
    for (std::size_t k = 0; k < n_scales; ++k) adjacency.emplace_back(senses.n_place(k), s.adjacency);
    NavigationRun run;
    const std::size_t n_goals = s.goals.size();
    run.visits.assign(n_goals, 0);
    // Per scale and goal: the reward cell (the most active inside the goal's radius) and its rate.
    std::vector<std::vector<int>> goal_cells(n_scales, std::vector<int>(n_goals, -1));
    std::vector<std::vector<double>> best(n_scales, std::vector<double>(n_goals, 0.0));

    // Learning.
    int n_cover_parts = 0;
    const auto cover_parts = cover_grid.parts(s.robot.radius, n_cover_parts);
    const int cover_main = largest_part(cover_parts, n_cover_parts);
    std::size_t free_cells = 0, covered = 0;
    for (int l : cover_parts) free_cells += l == cover_main;
    std::vector<char> visited(cover_grid.size(), 0);
    std::vector<char> inside(n_goals, 0);
    const auto walk = RandomWalkSpec(s.robot).make(&world, seed);
    const double learn_end = nav.max_learn_hours * 3600;
    for (std::int64_t k = 0;; ++k) {
        const auto step = walk->next(learn_end);
        if (!step) break;
        const Vec2 p(step->pose.x, step->pose.y);
        const auto& rates = senses.step(step->pose, true, step->bumped, step->t);
        const auto hd = hd_rates(step->pose.heading, s.adjacency.n_hd);
        for (std::size_t sc = 0; sc < n_scales; ++sc) adjacency[sc].learn(rates[sc], hd, step->bumped);
        if (k % 8 == 0) run.learn_path.push_back(p);
        if (const auto c = cover_grid.cell_of(p); c && !visited[cover_grid.index(*c)]) {
            visited[cover_grid.index(*c)] = 1;
            covered += cover_parts[cover_grid.index(*c)] == cover_main;
        }
        bool goals_done = true;
        for (std::size_t g = 0; g < n_goals; ++g) {
            const bool in = (p - s.goals[g]).norm() <= nav.goal_radius;
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
        memory.push_back({SparseAdjacency(adjacency[k]), s.reward.for_scale(k), {}});
        adjacency[k] = HdAdjacency(1, s.adjacency);  // its dense matrices are not needed any more
        for (std::size_t g = 0; g < n_goals; ++g)
            memory[k].rewards.push_back(goal_cells[k][g] >= 0
                                            ? replay(memory[k].adjacency, goal_cells[k][g], memory[k].reward)
                                            : std::vector<double>(std::size_t(senses.n_place(k)), 0.0));
    }
    // What a run reports: the first scale's (the model's own place cells).
    run.goal_cells = goal_cells.front();
    run.rewards = memory.front().rewards;
    int n_parts = 0;
    const auto parts = path_grid.parts(s.robot.radius, n_parts);
    const auto bounds = body->walkable().bounds();
    for (std::size_t g = 0; g < n_goals; ++g) {
        const Vec2 goal = s.goals[g];
        const auto& w = run.rewards[g];
        run.reward_maps.emplace_back();
        if (nav.reward_map_cell > 0)
            for (double y = bounds.min().y() + nav.reward_map_cell / 2; y < bounds.max().y(); y += nav.reward_map_cell)
                for (double x = bounds.min().x() + nav.reward_map_cell / 2; x < bounds.max().x();
                     x += nav.reward_map_cell) {
                    const Vec2 q(x, y);
                    if (!body->walkable().contains(q) || body->clearance(q) < 0) continue;
                    senses.reset();
                    for (int k = 0; k < std::max(1, nav.settle_steps); ++k)
                        senses.step(Pose::on_floor(x, y, 0.0), false);
                    run.reward_maps.back().push_back({q, reward(w, senses.rates().front())});
                }
        const int goal_part = parts[path_grid.index(*nearest_usable_cell(path_grid, goal, s.robot.radius))];
        Rng rng(hash_u64(seed, 0x6e617669676174ULL, g), Stream::walk);
        for (int i = 0; i < nav.starts; ++i) {
            NavigationStart out;
            out.goal = static_cast<int>(g);
            Vec2 p;
            for (int tries = 0;; ++tries) {
                if (tries > 100000)
                    throw InputError("navigation: no start at least " + format_number(nav.min_start_distance) +
                                     " m from " + goal_text(g, goal) + " on its floor");
                p = Vec2(rng.uniform(bounds.min().x(), bounds.max().x()),
                         rng.uniform(bounds.min().y(), bounds.max().y()));
                if ((p - goal).norm() >= nav.min_start_distance && body->walkable().contains(p) &&
                    body->clearance(p) >= 0.05 && part_of(path_grid, parts, p) == goal_part)
                    break;
            }
            out.start = p;
            out.shortest_m = shortest_path(path_grid, p, goal, nav.path_inflate).length;
            senses.reset();
            Pose pose = Pose::on_floor(p.x(), p.y(), rng.uniform(-pi, pi));
            for (int k = 0; k < std::max(1, nav.settle_steps); ++k) senses.step(pose, false);
            RewardPolicy policy(memory, g, senses, s.reward, rng);
            GoalSeekingWalk agent(body, s.robot, {s.adjacency.n_hd, nav.step, nav.clearance}, policy, pose);
            out.path.push_back(p);
            while (true) {
                const Vec2 here(agent.pose().x, agent.pose().y);
                if ((here - goal).norm() <= nav.success_radius) {
                    out.success = true;
                    break;
                }
                if (agent.travelled() >= nav.max_path_ratio * out.shortest_m) break;
                const auto step = agent.next(nav.max_hours * 3600);
                if (!step) break;
                senses.step(step->pose, false, step->bumped, step->t);
                out.path.emplace_back(step->pose.x, step->pose.y);
            }
            out.path_m = agent.travelled();
            out.time_s = agent.time();
            if (progress) progress(out);
            run.starts.push_back(std::move(out));
        }
    }
    return run;
}

}  // namespace bvc3d

#include "bvc3d/experiment/episodes.hpp"

#include <algorithm>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "bvc3d/agent/navigation_space.hpp"
#include "bvc3d/config/navigation_spec.hpp"
#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/experiment/model_network.hpp"
#include "bvc3d/navigation/failure_class.hpp"
#include "bvc3d/navigation/policy.hpp"
#include "bvc3d/navigation/replay.hpp"
#include "bvc3d/population/reward_cells.hpp"

namespace bvc3d {

namespace {

// The trial's model as the episodes step it: one model step at a time, learning as a policy sets it, and each scale's
// place-cell rates after the step.
class Senses : public NavigationSenses {
public:
    Senses(const World& world, const TrialConfig& trial) : net_(&world, {trial}, {}, false, 1) {
        const ModelSpec& model = trial.model;
        for (const std::string& name : model.place_scales()) scales_.push_back(node_of(model, name));
        for (std::size_t s = 0; s < scales_.size(); ++s)
            adjacencies_.push_back(node_of(model, NavigationSpec::adjacency_name(model, s)));
        rates_.resize(scales_.size());
    }
    // The node of the model's population `name` ("place" or one of ModelSpec::populations).
    std::size_t node_of(const ModelSpec& model, const std::string& name) const {
        const auto& nodes = net_.nodes.front();
        if (name == "place") return nodes.place;
        for (std::size_t k = 0; k < model.populations.size(); ++k)
            if (model.populations[k].name == name) return nodes.others[k];
        throw std::logic_error("navigation: the model has no population '" + name + "'");
    }
    std::size_t size() const { return net_.network.size(); }
    Population& population(std::size_t node) { return *net_.network.node(node).population; }
    const std::vector<std::vector<double>>& step(const Pose& pose, bool bumped, double t) override {
        net_.network.step(ModelStep{t, pose, bumped, std::nullopt}, index_++, learn_, false);
        for (std::size_t s = 0; s < scales_.size(); ++s) {
            const auto v = net_.network.latest(scales_[s]);
            rates_[s].assign(v.begin(), v.end());
        }
        return rates_;
    }
    const std::vector<std::vector<double>>& rates() const override { return rates_; }
    void reset() override {
        for (std::size_t i = 0; i < net_.network.size(); ++i) net_.network.node(i).population->reset_activity();
    }
    // The learned state reload() sets back (every population's; empty: reload() is not asked for).
    void keep(std::vector<std::vector<StateArray>> learned) { learned_ = std::move(learned); }
    void reload() override {
        if (learned_.size() != size()) throw std::logic_error("navigation: no learned state kept to reload");
        for (std::size_t i = 0; i < learned_.size(); ++i) population(i).restore(learned_[i]);
    }
    void set_learning(bool on) override { learn_ = on; }
    void settle(const Pose& pose, int steps) {
        reset();
        for (int k = 0; k < std::max(1, steps); ++k) step(pose, false, 0.0);
    }
    const HdAdjacency& adjacency(std::size_t s) const override {
        return dynamic_cast<const AdjacencyPopulation&>(*net_.network.node(adjacencies_.at(s)).population).adjacency();
    }
    // Every population's state from `learned`, but the adjacencies' unless `with_adjacencies`.
    void restore(const std::vector<std::vector<StateArray>>& learned, bool with_adjacencies) {
        for (std::size_t i = 0; i < learned.size(); ++i)
            if (with_adjacencies || std::find(adjacencies_.begin(), adjacencies_.end(), i) == adjacencies_.end())
                population(i).restore(learned[i]);
    }

private:
    ModelNetwork net_;
    std::vector<std::size_t> scales_, adjacencies_;  // the nodes of the place-cell scales and of their adjacencies
    std::int64_t index_ = 0;
    bool learn_ = false;
    std::vector<std::vector<double>> rates_;
    std::vector<std::vector<StateArray>> learned_;
};

// FNV-1a of a text: a seed from a world's name.
std::uint64_t text_seed(const std::string& text) {
    std::uint64_t h = 14695981039346656037ULL;
    for (unsigned char c : text) h = (h ^ c) * 1099511628211ULL;
    return h;
}

std::uint64_t bits_of(double v) {
    std::uint64_t b = 0;
    std::memcpy(&b, &v, sizeof b);
    return b;
}

// The streams of a goal's starts. bvc3d's protocol: one stream per learning run and goal draws the starts, their
// poses and every choice of the starts in turn. The authors' (SPEC §17.3): the starts and their poses from a stream
// of the world's name and the goal's coordinates alone (the same starts for every learning run), each start's
// choices from a stream of the learning run's seed, the goal and the start.
class StartStreams {
public:
    StartStreams(const NavigationParams& p, const std::string& world, std::uint64_t seed, std::size_t g,
                 const NavigationGoal& goal)
        : own_(p.protocol == NavigationProtocol::authors),
          seed_(seed),
          g_(g),
          starts_(own_ ? hash_u64(text_seed(world), bits_of(goal.x()), bits_of(goal.y()) ^ bits_of(goal.z()))
                       : hash_u64(seed, 0x6e617669676174ULL, g),
                  Stream::walk) {}
    Rng& starts() { return starts_; }
    // The stream of start i's choices.
    Rng& choices(int i) {
        if (!own_) return starts_;
        choices_.emplace(hash_u64(seed_, 0x63686f69636573ULL, (std::uint64_t(g_) << 32) | std::uint64_t(i)),
                         Stream::walk);
        return *choices_;
    }

private:
    bool own_;
    std::uint64_t seed_;
    std::size_t g_;
    Rng starts_;
    std::optional<Rng> choices_;
};

// Why a start failed (navigation/failure_class.hpp): its path and end, the yardstick's distances to the goal where
// its last quarter began and at its end (bvc3d's shortest path, whatever the protocol), goal g's reward map.
FailureClass failure_of(const StartRun& run, const NavigationSpace& space, const NavigationGoal& goal,
                        const std::vector<Vec2>& points, const std::vector<double>& map_reward, std::size_t g,
                        const NavigationParams& p) {
    if (run.success()) return FailureClass::none;
    FailedStart f;
    f.end = run.end;
    f.path = run.path;
    f.bumped = run.bumped;
    f.goal = goal.p.head<2>();
    f.distance_at_last_quarter = space.geodesic(run.path[tail_start(run.path, 0.25)], goal.p);
    f.distance_at_end = space.geodesic(run.path.back(), goal.p);
    f.map_points = points;
    f.map_values = std::span<const double>(map_reward).subspan(g * points.size(), points.size());
    f.map_cell = p.reward_map_cell;
    return classify_failure(f);
}

const StateArray& array_named(const std::vector<StateArray>& arrays, const std::string& name) {
    for (const StateArray& a : arrays)
        if (a.name == name) return a;
    throw InputError("navigation: a learned state lacks '" + name + "'");
}

}  // namespace

EpisodeOutcome run_episodes(const World& world, const TrialConfig& trial, std::vector<std::vector<StateArray>> learned,
                            const EpisodeControl& control) {
    if (!trial.navigation) throw std::logic_error("run_episodes: not a navigation trial");
    const NavigationSpec& nav = *trial.navigation;
    const NavigationParams& p = nav.space.nav;
    const auto space = make_navigation_space(world.description(), nav.space);
    Senses senses(world, trial);
    if (learned.size() != senses.size())
        throw InputError("navigation: the learned state holds " + std::to_string(learned.size()) +
                         " populations, the model " + std::to_string(senses.size()));
    const ModelSpec& model = trial.model;
    const auto scale_names = model.place_scales();
    const std::size_t n_scales = scale_names.size(), n_goals = nav.space.goals.size();
    const AdjacencyParams adjacency = nav.adjacency_params();

    EpisodeOutcome out;
    NavigationRecord& rec = out.record;
    rec.dims = nav.space.dims();
    for (const NavigationGoal& g : nav.space.goals)
        for (int d = 0; d < rec.dims; ++d) rec.goals.push_back(g.p[d]);
    rec.scales = scale_names;

    // Per scale: the frozen copies of its adjacency (the learned matrices let go once copied, unless the policy learns
    // while it exploits and reloads them at each start), its reward cells' bound cells and, by replay from them,
    // their weights.
    const PolicySpec& policy = *nav.policy;
    std::vector<ScaleMemory> memory;
    for (std::size_t s = 0; s < n_scales; ++s) {
        const std::size_t adj_node = senses.node_of(model, NavigationSpec::adjacency_name(model, s));
        const std::size_t reward_node = senses.node_of(model, NavigationSpec::reward_name(model, s));
        const auto n_place = static_cast<int>(senses.population(senses.node_of(model, scale_names[s])).size());
        {
            HdAdjacency adj(n_place, adjacency);
            adj.restore(learned[adj_node]);
            if (!policy.learns()) learned[adj_node].clear();
            memory.push_back(scale_memory(adj, adjacency, nav.reward.for_scale(s)));
        }
        auto& reward_state = learned[reward_node];
        const auto& cells = std::get<std::vector<double>>(array_named(reward_state, "reward_cells").values);
        std::vector<double> weights;
        for (std::size_t g = 0; g < n_goals; ++g) {
            const int cell = static_cast<int>(cells[g]);
            rec.goal_cells.push_back(cell);
            memory[s].rewards.push_back(cell >= 0 ? replay(*memory[s].sparse, cell, memory[s].reward)
                                                  : std::vector<double>(std::size_t(n_place), 0.0));
            weights.insert(weights.end(), memory[s].rewards.back().begin(), memory[s].rewards.back().end());
        }
        for (StateArray& a : reward_state)
            if (a.name == "reward_weights") a.values = std::move(weights);
    }
    // The model as learned; its adjacencies stay as made (navigation reads the frozen copies, and nothing learns)
    // unless the policy learns while it exploits: then every start sets the whole learned state back.
    senses.restore(learned, policy.learns());
    if (policy.learns()) senses.keep(learned);

    for (const auto& wall : space->walls())
        for (const Vec2& end : wall) rec.walls.push_back(end.x()), rec.walls.push_back(end.y());

    // The first scale's reward map: the model settled at each point, read out for every goal.
    const auto points = space->map_points(p.reward_map_cell);
    rec.map_reward.assign(n_goals * points.size(), 0.0);
    for (std::size_t m = 0; m < points.size(); ++m) {
        rec.map_points.push_back(points[m].x());
        rec.map_points.push_back(points[m].y());
        senses.settle(Pose::on_floor(points[m].x(), points[m].y(), 0.0), p.settle_steps);
        for (std::size_t g = 0; g < n_goals; ++g)
            rec.map_reward[g * points.size() + m] = reward_readout(memory.front().rewards[g], senses.rates().front());
    }

    const auto controller =
        policy.make(PolicyContext{world, *space, nav.space, senses, memory, nav.reward, model.sensor});
    const std::size_t total = n_goals * std::size_t(p.starts);
    rec.path_start.push_back(0);
    for (std::size_t g = 0; g < n_goals; ++g) {
        const NavigationGoal& goal = nav.space.goals[g];
        StartStreams streams(p, world.name(), trial.seed, g, goal);
        for (int i = 0; i < p.starts; ++i) {
            if (control.stop && control.stop->load()) throw Interrupted();
            const Vec3 start = space->draw_start(streams.starts(), g, goal, p.min_start_distance);
            const double shortest = space->shortest(start, goal.p);
            const Pose pose = space->start_pose(start, streams.starts());
            const StartRun run = controller->run(
                pose, StartTask{g, goal.p, p.success_radius, p.max_path_ratio * shortest, p.max_hours * 3600},
                streams.choices(i));
            for (const Vec3& at : run.path)
                for (int d = 0; d < rec.dims; ++d) rec.path.push_back(at[d]);
            rec.start_goal.push_back(static_cast<int>(g));
            for (int d = 0; d < rec.dims; ++d) rec.start.push_back(start[d]);
            rec.success.push_back(run.success() ? 1 : 0);
            rec.path_m.push_back(run.path_m);
            rec.shortest_m.push_back(shortest);
            rec.time_s.push_back(run.time_s);
            rec.path_start.push_back(rec.path_start.back() + run.path.size());
            rec.failure.push_back(static_cast<int>(failure_of(run, *space, goal, points, rec.map_reward, g, p)));
            if (control.progress) control.progress(rec.n_starts(), total);
        }
    }
    out.states = std::move(learned);
    return out;
}

}  // namespace bvc3d

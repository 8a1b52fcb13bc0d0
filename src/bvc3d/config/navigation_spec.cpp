#include "bvc3d/config/navigation_spec.hpp"

#include <algorithm>

#include "bvc3d/agent/learning_walk.hpp"
#include "bvc3d/config/population_kinds.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d {

void NavigationSpec::validate() const {
    space.nav.validate();
    space.robot.validate();
    space.flight.validate();
    adjacency.validate();
    reward.validate();
    space.check_goals_shape();
    policy->validate();
    policy->check_dims(space.dims());
    if (space.nav.protocol == NavigationProtocol::authors && space.dims() != 2)
        NavigationParams::table().fail("protocol", "authors poses and scores starts on the floor; goals of " +
                                                       std::to_string(space.dims()) + " coordinates fly");
}

std::string NavigationSpec::adjacency_name(const ModelSpec& model, std::size_t scale) {
    return scale == 0 ? "adjacency" : "adjacency-" + model.place_scales().at(scale);
}

std::string NavigationSpec::reward_name(const ModelSpec& model, std::size_t scale) {
    return scale == 0 ? "reward" : "reward-" + model.place_scales().at(scale);
}

void NavigationSpec::check_model(const ModelSpec& model) const {
    const auto scales = model.place_scales();
    const std::size_t given = reward.scale_lambdas.size() + 1;
    if (scales.size() > given)
        RewardParams::table().fail("scale_lambdas", "gives λ for " + std::to_string(given) +
                                                        " scales (with lambda), but '" + model.name + "' has " +
                                                        std::to_string(scales.size()) + " scales of place cells");
    std::vector<std::string> added;
    if (hd_population(model).name == hd_name) added.push_back(hd_name);
    for (std::size_t s = 0; s < scales.size(); ++s)
        added.push_back(adjacency_name(model, s)), added.push_back(reward_name(model, s));
    for (const PopulationSpec& p : model.populations)
        if (std::find(added.begin(), added.end(), p.name) != added.end())
            throw InputError("model '" + model.name + "' has a population named '" + p.name +
                             "', a name navigation gives its own populations (nav-hd, adjacency…, reward…)");
}

AdjacencyParams NavigationSpec::adjacency_params() const {
    AdjacencyParams p = adjacency;
    p.n_hd = navigation_directions(space);
    return p;
}

PopulationSpec NavigationSpec::hd_population(const ModelSpec& base) const {
    HeadDirectionParams hd;
    hd.n = adjacency.n_hd;
    hd.space = space.dims() == 3 ? HdSpace::spherical : HdSpace::planar;
    PopulationSpec spec = config::head_direction_spec(hd_name, hd);
    spec.recorded = false;
    for (const PopulationSpec& p : base.populations)
        if (p.key == spec.key) return p;
    return spec;
}

ModelSpec NavigationSpec::model_for(const ModelSpec& base) const {
    check_model(base);
    ModelSpec m = base;
    const PopulationSpec hd = hd_population(base);
    if (hd.name == hd_name) m.populations.push_back(hd);
    RewardCellParams cells;
    cells.dims = space.dims();
    cells.radius = space.nav.goal_radius;
    for (const NavigationGoal& g : space.goals)
        for (int d = 0; d < cells.dims; ++d) cells.goals.push_back(g.p[d]);
    const auto scales = base.place_scales();
    for (std::size_t s = 0; s < scales.size(); ++s) {
        m.populations.push_back(
            config::adjacency_spec(adjacency_name(base, s), adjacency_params(), {scales[s], hd.name}));
        m.populations.push_back(config::reward_cells_spec(reward_name(base, s), cells, {scales[s]}));
    }
    return m;
}

std::shared_ptr<const AgentSpec> NavigationSpec::learning_walk() const {
    return std::make_shared<LearningWalkSpec>(space);
}

Protocol NavigationSpec::protocol() const {
    Protocol p;
    p.kind = Protocol::Kind::learn;
    p.explore_hours = space.nav.max_learn_hours;
    p.sample_hours = 0;
    return p;
}

std::string NavigationSpec::canonical() const {
    std::string goals;
    for (const NavigationGoal& g : space.goals)
        goals += " [" + format_number(g.x()) + ", " + format_number(g.y()) +
                 (g.dims == 3 ? ", " + format_number(g.z()) : "") + "]";
    std::string policy_text;
    const std::string policy_params = policy->canonical("    ");
    if (policy->name() != default_policy_kind().name || !policy_params.empty()) {
        policy_text = "  policy: " + policy->name() + "\n";
        if (!policy_params.empty()) policy_text += "  " + policy_kind(policy->name()).section + ":\n" + policy_params;
    }
    return "navigation:\n  goals:" + goals + "\n" + params::yaml_lines(NavigationParams::table(), space.nav, "  ") +
           policy_text + "reward:\n" + params::yaml_lines(RewardParams::table(), reward, "  ") + "adjacency:\n" +
           params::yaml_lines(AdjacencyParams::table(), adjacency_params(), "  ");
}

TrialConfig navigation_trial(const WorldSpec& world, const ModelSpec& base, std::shared_ptr<const NavigationSpec> nav,
                             std::uint64_t seed) {
    nav->validate();
    // The base model on the learning walk's body, as a trial checks it (a flying preset on the floor is refused).
    TrialConfig plain;
    plain.model = base;
    plain.set_agent(navigation_walk(nav->space));
    plain.validate();
    TrialConfig t;
    t.world = world;
    t.model = nav->model_for(base);
    t.set_agent(nav->learning_walk());
    t.protocol = nav->protocol();
    t.seed = seed;
    t.navigation = std::move(nav);
    return t;
}

}  // namespace bvc3d

#pragma once
// Config stage: what a navigation trial is (SPEC §17, docs/navigation.md): a model with navigation's populations, a
// learning walk, and the episodes after it. Takes: the goals, the navigation's parameter tables (navigation:,
// adjacency:, reward:, flight:, robot:), the policy (config/policy_kinds.hpp) and a model. Gives: the trial's model
// (its own populations, plus an HD population, and per scale of place cells an adjacency and reward cells), its agent
// (the learning walk), its protocol (learn), and the canonical text of what the episodes depend on (in the trial's
// fingerprint).
#include <memory>
#include <string>
#include <vector>

#include "bvc3d/agent/navigation_space.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/config/policy_kinds.hpp"
#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/navigation/reward_params.hpp"
#include "bvc3d/population/hd_adjacency.hpp"

namespace bvc3d {

struct NavigationSpec {
    NavigationSpaceSpec space;  // goals, navigation:, robot:, flight:
    AdjacencyParams adjacency;  // its n_hd is the floor's number of directions (flying: the 20 HD cells')
    RewardParams reward;
    std::shared_ptr<const PolicySpec> policy = default_policy();  // the controller of the episodes
    // The tables' checks, the goals' shape and whether the policy moves in their space (InputError naming the key
    // or goal).
    void validate() const;
    // InputError naming reward.scale_lambdas if `model` has more scales of place cells than λs are given for, or if
    // it already has a population of a name navigation adds (nav-hd, adjacency…, reward…).
    void check_model(const ModelSpec& model) const;
    // The populations navigation adds to a model, by scale (ModelSpec::place_scales()): their names.
    static std::string adjacency_name(const ModelSpec& model, std::size_t scale);
    static std::string reward_name(const ModelSpec& model, std::size_t scale);
    // The HD population the adjacencies read: `base`'s own if it has one of the kind and size they need (ms-2d's
    // "hd"), else navigation's, named nav-hd.
    PopulationSpec hd_population(const ModelSpec& base) const;
    static constexpr const char* hd_name = "nav-hd";
    ModelSpec model_for(const ModelSpec& base) const;
    std::shared_ptr<const AgentSpec> learning_walk() const;
    Protocol protocol() const;
    AdjacencyParams adjacency_params() const;  // with n_hd the space's directions
    // What the episodes depend on beyond the model and the learning walk: the navigation's keys, reward:, the goals,
    // and the policy with its parameters unless it is the default policy at its defaults (so that trials of
    // today's policy keep their fingerprints).
    std::string canonical() const;
};

// A navigation trial of `base` in `world` with `seed`: TrialConfig::navigation set, the model, agent and protocol
// as NavigationSpec gives them. InputError if the base model is a preset for the other way of moving.
TrialConfig navigation_trial(const WorldSpec& world, const ModelSpec& base, std::shared_ptr<const NavigationSpec> nav,
                             std::uint64_t seed);

}  // namespace bvc3d

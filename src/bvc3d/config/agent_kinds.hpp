#pragma once
// Config stage: the kinds of agent (agent/), in one registry — how a trial YAML finds an agent by its
// key (`robot:`, `trajectory:`, `flight:`), and the command line's --agent and Python's agent= by
// name. A new kind of agent is its Agent and AgentSpec in agent/ and one entry here.
// Takes: a name, or a trial's YAML mapping. Gives: the agent's spec.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bvc3d/agent/agent.hpp"
#include "bvc3d/config/yaml_reader.hpp"

namespace bvc3d {

struct AgentKind {
    std::string name;                  // the kind() of its specs: random_walk, trajectory, flight
    std::vector<std::string> aliases;  // other names it goes by: ground, flying
    std::string yaml_key;              // the trial YAML key that gives it: robot, trajectory, flight
    std::string description;           // what it is, for help texts and messages
    std::string protocol;              // the protocol its experiments run unless told otherwise (protocols.hpp)
    // The agent with its default parameters; null for a kind that needs data (a trajectory's rows),
    // which is not chosen by name.
    std::function<std::shared_ptr<const AgentSpec>()> make_default;
    // The agent from the value of its YAML key (files relative to the YAML file), errors at the key.
    std::function<std::shared_ptr<const AgentSpec>(const config::YamlView&)> from_yaml;
};

// random_walk (the default agent, first), trajectory, flight.
const std::vector<AgentKind>& agent_kinds();
// A kind chosen by its name or an alias, among those with default parameters; InputError naming them
// for any other name.
const AgentKind& agent_kind(const std::string& name);
// The registered kind of a spec (by its kind()); InputError for a spec of a kind not registered.
const AgentKind& agent_kind_of(const AgentSpec& spec);
// The kinds that can be chosen by name, as help texts list them: "random_walk or ground (...), ...".
std::string agent_names_text();
// An agent by name, with its default parameters (the CLI's --agent, Python's agent=).
std::shared_ptr<const AgentSpec> agent_by_name(const std::string& name);

namespace config {

// The trial YAML keys of the kinds, in the registry's order.
std::vector<std::string> agent_yaml_keys();
// The agent a trial's mapping gives: the kind whose key it holds (at most one), else the default agent.
std::shared_ptr<const AgentSpec> agent_from_yaml(const YamlView& trial);

}  // namespace config

}  // namespace bvc3d

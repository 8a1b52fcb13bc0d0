#include "bvc3d/config/agent_kinds.hpp"

#include "bvc3d/agent/flying_walk.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d {

const std::vector<AgentKind>& agent_kinds() {
    static const std::vector<AgentKind> kinds{
        {"random_walk",
         {"ground"},
         "robot",
         "the paper's ground robot",
         "paper",
         [] { return std::make_shared<RandomWalkSpec>(); },
         [](const config::YamlView& v) {
             RobotParams robot;
             config::read_table(v, robot, RobotParams::table());
             return std::make_shared<RandomWalkSpec>(robot);
         }},
        {"trajectory",
         {},
         "trajectory",
         "a given path: a file of t, x, y, [z], heading rows",
         "paper",
         nullptr,
         [](const config::YamlView& v) -> std::shared_ptr<const AgentSpec> {
             // `trajectory: FILE`, or a mapping: `file: FILE` and the keys of TrajectoryParams.
             TrajectoryParams params;
             const config::YamlView file = v.is_map() ? v["file"] : v;
             if (v.is_map()) config::read_table(v, params, TrajectoryParams::table(), {"file"});
             try {
                 return std::make_shared<TrajectorySpec>(
                     TrajectorySpec::from_file(config::path_in_file(file, file.as_string()), params));
             } catch (const ConfigError&) {
                 throw;
             } catch (const InputError& e) {
                 file.fail(e.what());
             }
         }},
        {"flight",
         {"flying"},
         "flight",
         "the flying agent, docs/flying.md",
         "flight",
         [] { return std::make_shared<FlightSpec>(); },
         [](const config::YamlView& v) {
             FlightParams flight;
             config::read_table(v, flight, FlightParams::table());
             return std::make_shared<FlightSpec>(flight);
         }},
    };
    return kinds;
}

const AgentKind& agent_kind(const std::string& name) {
    for (const auto& k : agent_kinds()) {
        if (!k.make_default) continue;
        if (k.name == name) return k;
        for (const auto& alias : k.aliases)
            if (alias == name) return k;
    }
    throw InputError("agent '" + name + "' is not one of " + agent_names_text());
}

const AgentKind& agent_kind_of(const AgentSpec& spec) {
    for (const auto& k : agent_kinds())
        if (k.name == spec.kind()) return k;
    throw InputError("agent kind '" + spec.kind() + "' is not registered (config/agent_kinds.hpp)");
}

std::string agent_names_text() {
    std::string text;
    for (const auto& k : agent_kinds()) {
        if (!k.make_default) continue;
        text += (text.empty() ? "" : ", ") + k.name;
        for (const auto& alias : k.aliases) text += " or " + alias;
        text += " (" + k.description + ")";
    }
    return text;
}

std::shared_ptr<const AgentSpec> agent_by_name(const std::string& name) { return agent_kind(name).make_default(); }

namespace config {

std::vector<std::string> agent_yaml_keys() {
    std::vector<std::string> keys;
    for (const auto& k : agent_kinds()) keys.push_back(k.yaml_key);
    return keys;
}

std::shared_ptr<const AgentSpec> agent_from_yaml(const YamlView& trial) {
    const AgentKind* given = nullptr;
    for (const auto& k : agent_kinds()) {
        if (!trial.has(k.yaml_key)) continue;
        if (given) {
            std::string keys;
            for (const auto& other : agent_kinds())
                keys += (keys.empty() ? "'" : "', '") + other.yaml_key + "' (" + other.description + ")";
            trial.fail("give one agent: one of " + keys + ", not several");
        }
        given = &k;
    }
    if (!given) return agent_kinds().front().make_default();
    return given->from_yaml(trial[given->yaml_key]);
}

}  // namespace config

}  // namespace bvc3d

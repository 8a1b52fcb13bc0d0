#pragma once
// Config stage: the protocols experiments run, as named configurations in one table: `paper` (the
// paper's 4 h of exploration, then 4 h of sampling: the Protocol struct's defaults) and `flight`
// (8 h + 8 h, the flying agents' experiment, docs/flying.md). `bvc3d paper`, `bvc3d flight`,
// Python's run_trial and the agent kinds (agent_kinds.hpp) name them here.
// Takes: a name. Gives: a Protocol.
#include <string>
#include <vector>

#include "bvc3d/config/trial_config.hpp"

namespace bvc3d {

struct ProtocolPreset {
    std::string name, description;
    Protocol protocol;
};

const std::vector<ProtocolPreset>& protocol_presets();
const Protocol& protocol_preset(const std::string& name);  // InputError naming the presets for another name
// "4 + 4": a protocol's hours as help texts state them.
std::string protocol_hours_text(const Protocol& p);

}  // namespace bvc3d

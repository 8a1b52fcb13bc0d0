#include "bvc3d/config/protocols.hpp"

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d {

namespace {

Protocol both_phases(double hours) {
    Protocol p;
    p.explore_hours = p.sample_hours = hours;
    return p;
}

}  // namespace

const std::vector<ProtocolPreset>& protocol_presets() {
    static const std::vector<ProtocolPreset> presets{
        {"paper", "the paper's: exploration with learning on, then sampling with learning frozen", Protocol{}},
        {"flight", "the flying agents' (docs/flying.md): twice the paper's, since 3-D needs more coverage than 2-D",
         both_phases(8.0)},
    };
    return presets;
}

const Protocol& protocol_preset(const std::string& name) {
    std::string names;
    for (const auto& p : protocol_presets()) {
        if (p.name == name) return p.protocol;
        names += (names.empty() ? "" : ", ") + p.name;
    }
    throw InputError("protocol preset '" + name + "' is not one of " + names);
}

std::string protocol_hours_text(const Protocol& p) {
    if (p.kind == Protocol::Kind::online) return format_number(p.sample_hours);
    return format_number(p.explore_hours) + " + " + format_number(p.sample_hours);
}

}  // namespace bvc3d

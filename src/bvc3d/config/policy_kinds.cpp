#include "bvc3d/config/policy_kinds.hpp"

#include "bvc3d/core/error.hpp"
#include "bvc3d/navigation/authors_policy.hpp"
#include "bvc3d/navigation/rollout_policy.hpp"

namespace bvc3d {

const std::vector<PolicyKind>& policy_kinds() {
    static const std::vector<PolicyKind> kinds{
        {RolloutPolicySpec::kind,
         "bvc3d's first controller: every 0.25 m one of the HD directions, drawn from one straight 3-step rollout per "
         "direction (docs/navigation.md#the-model)",
         "", [] { return std::make_shared<RolloutPolicySpec>(); }, nullptr},
        {AuthorsPolicySpec::kind,
         "the authors' controller (SPEC §17.2): 1.43 m blocks along a continuous heading from 10 turning rollouts per "
         "direction, the scales mixed by entropy and reliability, LiDAR safety, exploration and loop recovery "
         "(docs/navigation.md#the-authors-controller)",
         "authors", [] { return std::make_shared<AuthorsPolicySpec>(); },
         [](const config::YamlView& v) {
             AuthorsParams p;
             config::read_table(v, p, AuthorsParams::table());
             return std::make_shared<AuthorsPolicySpec>(p);
         }},
    };
    return kinds;
}

const PolicyKind& default_policy_kind() { return policy_kinds().front(); }

const PolicyKind& policy_kind(const std::string& name) {
    for (const auto& k : policy_kinds())
        if (k.name == name) return k;
    throw InputError("policy '" + name + "' is not one of " + policy_names_text());
}

std::string policy_names_text() {
    std::string text;
    for (const auto& k : policy_kinds()) text += (text.empty() ? "" : ", ") + k.name + " (" + k.doc + ")";
    return text;
}

std::shared_ptr<const PolicySpec> default_policy() { return default_policy_kind().make_default(); }

namespace config {

std::vector<std::string> policy_yaml_keys() {
    std::vector<std::string> keys{"policy"};
    for (const auto& k : policy_kinds())
        if (!k.section.empty()) keys.push_back(k.section);
    return keys;
}

std::shared_ptr<const PolicySpec> policy_named(const std::string& name, const YamlView* section) {
    const PolicyKind& kind = policy_kind(name);
    if (!section) return kind.make_default();
    if (!kind.from_yaml) section->fail("policy '" + name + "' takes no parameters");
    return kind.from_yaml(*section);
}

std::shared_ptr<const PolicySpec> policy_from_yaml(const YamlView& v) {
    std::string name = default_policy_kind().name;
    if (v.has("policy")) {
        name = v["policy"].as_string();
        try {
            policy_kind(name);
        } catch (const InputError& e) {
            v["policy"].fail(e.what());
        }
    }
    const PolicyKind& kind = policy_kind(name);
    for (const auto& other : policy_kinds())
        if (!other.section.empty() && other.name != name && v.has(other.section))
            v[other.section].fail("the parameters of policy '" + other.name + "', but the policy is '" + name +
                                  "' (policy: " + other.name + " to use them)");
    if (!kind.section.empty() && v.has(kind.section)) {
        const YamlView section = v[kind.section];
        return policy_named(name, &section);
    }
    return policy_named(name);
}

}  // namespace config

}  // namespace bvc3d

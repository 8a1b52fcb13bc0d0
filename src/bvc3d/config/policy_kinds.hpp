#pragma once
// Config stage: the navigation policies (navigation/policy.hpp), one list — how navigate's --policy, a YAML's
// `policy:` (navigate's file and a trial's navigation: section) and Python's policy= find a controller by name, and
// where its parameters are read (a section named after it beside `policy:`, e.g. `authors: {learn: false}`).
// A new policy is its PolicySpec and controller in navigation/ and one row here.
// Takes: a name, or a YAML mapping. Gives: the policy's spec.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bvc3d/config/yaml_reader.hpp"
#include "bvc3d/navigation/policy.hpp"

namespace bvc3d {

struct PolicyKind {
    std::string name;     // PolicySpec::name()
    std::string doc;      // what it is, for help texts and messages
    std::string section;  // the YAML key of its parameters beside `policy:`; "" for a policy without any
    std::function<std::shared_ptr<const PolicySpec>()> make_default;
    // The policy with the parameters of its section `v` (errors at the key); null for a policy without parameters.
    std::function<std::shared_ptr<const PolicySpec>(const config::YamlView& v)> from_yaml;
};

// The first is the default: rollout8 (bvc3d's first controller); then authors (SPEC §17.2).
const std::vector<PolicyKind>& policy_kinds();
const PolicyKind& default_policy_kind();
// InputError naming the policies for an unknown name.
const PolicyKind& policy_kind(const std::string& name);
// "rollout8 (…), authors (…)": what help texts list.
std::string policy_names_text();
// The default policy with its default parameters.
std::shared_ptr<const PolicySpec> default_policy();

namespace config {

// The keys a mapping may hold for the policy: `policy` and every policy's section.
std::vector<std::string> policy_yaml_keys();
// The policy a mapping names (`policy: NAME`; the default when absent), with its section's parameters; a section of
// another policy than the one named is an error at its key.
std::shared_ptr<const PolicySpec> policy_from_yaml(const YamlView& v);
// The policy `name` with the parameters of `section` (a mapping; none: its defaults); InputError naming the policy or
// the key.
std::shared_ptr<const PolicySpec> policy_named(const std::string& name, const YamlView* section = nullptr);

}  // namespace config

}  // namespace bvc3d

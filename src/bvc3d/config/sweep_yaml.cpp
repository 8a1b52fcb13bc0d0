#include "bvc3d/config/sweep_yaml.hpp"

#include <filesystem>
#include <sstream>

#include "bvc3d/config/trial_yaml.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d::config {

namespace {

std::vector<std::string> split_key(const std::string& key) {
    std::vector<std::string> parts;
    std::stringstream ss(key);
    for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
    return parts;
}

// Sets the dotted `key` of `root` to `value`, creating mappings on the way. A preset name where a
// mapping is needed becomes one: `model: 3d-0.2` -> `{base: 3d-0.2}`, `world: cross` -> `{source: cross}`.
void set_key(YAML::Node root, const std::string& key, const YAML::Node& value, const YamlView& where) {
    const auto parts = split_key(key);
    if (parts.empty()) where.fail("empty key");
    YAML::Node node = root;
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
        YAML::Node child = node[parts[i]];
        if (!child.IsDefined() || child.IsNull()) {
            node[parts[i]] = YAML::Node(YAML::NodeType::Map);
        } else if (child.IsScalar()) {
            const std::string promoted = i == 0 && parts[i] == "model"   ? "base"
                                         : i == 0 && parts[i] == "world" ? "source"
                                                                         : "";
            if (promoted.empty()) where.fail("'" + parts[i] + "' is a value, so '" + key + "' cannot be set inside it");
            YAML::Node m(YAML::NodeType::Map);
            m[promoted] = child.Scalar();
            node[parts[i]] = m;
        } else if (!child.IsMap()) {
            where.fail("'" + parts[i] + "' is a list, so '" + key + "' cannot be set inside it");
        }
        node.reset(node[parts[i]]);
    }
    node[parts.back()] = YAML::Clone(value);
}

// A short text for a value in labels: [0.0, 0.2] -> 0-0.2.
std::string value_text(const YAML::Node& v) {
    if (v.IsScalar()) return v.Scalar();
    std::string out;
    if (v.IsSequence())
        for (std::size_t i = 0; i < v.size(); ++i) out += (i ? "-" : "") + value_text(v[i]);
    else out = "map";
    return out;
}

std::string sanitize(const std::string& s) {
    std::string out;
    for (char c : s) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '+') ? c : '_';
    return out;
}

std::string yaml_text(const YAML::Node& v) {
    YAML::Emitter e;
    e << YAML::Flow << v;
    return e.c_str();
}

// One condition: the swept keys and their values, and where in the file it was written.
struct Condition {
    std::vector<std::pair<std::string, YAML::Node>> values;
    YamlView where;
};

// Every combination of the grid's values, first key slowest.
std::vector<Condition> grid_conditions(const YamlView& grid, std::vector<std::string>& keys) {
    std::vector<std::pair<std::string, YamlView>> axes;
    for (const auto& key : grid.keys()) {
        if (key == "seed") grid.fail_key(key, "seeds are not a grid key: list them under 'seeds:'");
        const YamlView values = grid[key];
        if (!values.is_sequence()) values.fail("expected a list of values to sweep");
        if (values.size() == 0) values.fail("lists no values: an empty grid runs nothing");
        axes.emplace_back(key, values);
        keys.push_back(key);
    }
    if (axes.empty()) grid.fail("has no keys");
    double n = 1;
    for (const auto& a : axes) n *= static_cast<double>(a.second.size());
    if (n > max_trials)
        grid.fail("makes " + format_number(n) + " conditions; the limit is " +
                  std::to_string(static_cast<long long>(max_trials)) + " trials");
    std::vector<Condition> conditions;
    std::vector<std::size_t> idx(axes.size(), 0);
    for (bool more = true; more;) {
        Condition c{{}, axes.back().second.at(idx.back())};
        for (std::size_t a = 0; a < axes.size(); ++a)
            c.values.emplace_back(axes[a].first, axes[a].second.at(idx[a]).node());
        conditions.push_back(c);
        more = false;
        for (std::size_t a = axes.size(); a-- > 0;) {
            if (++idx[a] < axes[a].second.size()) {
                more = true;
                break;
            }
            idx[a] = 0;
        }
    }
    return conditions;
}

// The explicit list of conditions, each a mapping of keys to values.
std::vector<Condition> list_conditions(const YamlView& list, std::vector<std::string>& keys) {
    if (list.size() == 0) list.fail("is empty");
    std::vector<Condition> conditions;
    for (std::size_t i = 0; i < list.size(); ++i) {
        const YamlView item = list.at(i);
        if (!item.is_map() || item.keys().empty()) item.fail("each condition is a mapping of keys to values");
        Condition c{{}, item};
        for (const auto& key : item.keys()) {
            if (key == "seed") item.fail_key(key, "seeds are not a condition key: list them under 'seeds:'");
            c.values.emplace_back(key, item[key].node());
            if (std::find(keys.begin(), keys.end(), key) == keys.end()) keys.push_back(key);
        }
        conditions.push_back(c);
    }
    return conditions;
}

// `seeds: N` (0 .. N-1) or a list of seeds (each 0 .. 2^64 - 1); default: seed 0.
std::vector<std::uint64_t> read_seeds(const YamlView& v) {
    if (!v.has("seeds")) return {0};
    const YamlView s = v["seeds"];
    std::vector<std::uint64_t> seeds;
    if (s.is_scalar()) {
        const std::uint64_t n = s.as_uint64();
        if (n < 1) s.fail("must be >= 1 (a number of seeds) or a list of seeds");
        if (static_cast<double>(n) > max_trials)
            s.fail("asks for " + std::to_string(n) + " seeds; the limit is " +
                   std::to_string(static_cast<long long>(max_trials)) + " trials");
        for (std::uint64_t i = 0; i < n; ++i) seeds.push_back(i);
        return seeds;
    }
    if (s.size() == 0) s.fail("lists no seeds");
    if (static_cast<double>(s.size()) > max_trials)
        s.fail("lists " + std::to_string(s.size()) + " seeds; the limit is " +
               std::to_string(static_cast<long long>(max_trials)) + " trials");
    for (std::size_t i = 0; i < s.size(); ++i) seeds.push_back(s.at(i).as_uint64());
    return seeds;
}

// The base trial with one condition's values set, checked as a trial file would be.
TrialConfig condition_trial(const std::string& path, const YAML::Node& base, const Condition& c, std::size_t index) {
    YAML::Node tree = YAML::Clone(base);
    if (!tree.IsMap()) tree = YAML::Node(YAML::NodeType::Map);
    std::string label = std::to_string(index);
    label = "c" + std::string(label.size() < 3 ? 3 - label.size() : 0, '0') + label;
    std::vector<std::pair<std::string, std::string>> swept;
    for (const auto& [key, value] : c.values) {
        set_key(tree, key, value, c.where);
        label += "_" + sanitize(split_key(key).back()) + "=" + sanitize(value_text(value));
        swept.emplace_back(key, yaml_text(value));
    }
    TrialConfig t;
    try {
        t = trial_from_yaml(YamlView(tree, path, ""));
    } catch (const ConfigError& e) {
        // The message's line refers to the assembled trial; point at the sweep file's instead.
        std::string reason = e.reason();
        if (const auto at = reason.rfind(" (line "); at != std::string::npos) reason.resize(at);
        std::string values;
        for (const auto& [k, val] : swept) values += (values.empty() ? "" : ", ") + k + "=" + val;
        const int line = c.where.node().Mark().line;
        throw ConfigError(path, e.key(),
                          reason + " (in condition " + std::to_string(index) + ": " + values +
                              (line >= 0 ? ", line " + std::to_string(line + 1) : std::string()) + ")");
    }
    t.condition = label;
    t.swept = swept;
    t.origin = path + ", condition " + std::to_string(index);
    return t;
}

}  // namespace

Sweep load_sweep_file(const std::string& path) {
    const YamlView v = YamlView::load_file(path);
    v.expect_map({"name", "base", "grid", "list", "seeds"});
    Sweep sweep;
    sweep.name = v.get("name", std::filesystem::path(path).stem().string());
    const YAML::Node base = v.has("base") ? v["base"].node() : YAML::Node(YAML::NodeType::Map);
    if (v.has("base")) v["base"].expect_map(trial_keys());
    if (!v.has("grid") && !v.has("list")) v.fail("a sweep needs a 'grid' and/or a 'list' of conditions");
    std::vector<Condition> conditions;
    if (v.has("grid")) conditions = grid_conditions(v["grid"], sweep.keys);
    if (v.has("list")) {
        auto listed = list_conditions(v["list"], sweep.keys);
        conditions.insert(conditions.end(), listed.begin(), listed.end());
    }
    const auto seeds = read_seeds(v);
    const double n_trials = static_cast<double>(conditions.size()) * static_cast<double>(seeds.size());
    if (n_trials > max_trials)
        v.fail(std::to_string(conditions.size()) + " conditions × " + std::to_string(seeds.size()) + " seeds = " +
               format_number(n_trials) + " trials; the limit is " + std::to_string(static_cast<long long>(max_trials)));
    for (std::size_t c = 0; c < conditions.size(); ++c) {
        TrialConfig t = condition_trial(path, base, conditions[c], c);
        for (auto s : seeds) {
            t.seed = s;
            sweep.trials.push_back(t);
        }
    }
    return sweep;
}

}  // namespace bvc3d::config

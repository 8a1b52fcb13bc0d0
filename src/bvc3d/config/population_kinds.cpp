#include "bvc3d/config/population_kinds.hpp"

#include <algorithm>
#include <memory>

#include "bvc3d/core/random.hpp"
#include "bvc3d/population/bvc_population.hpp"
#include "bvc3d/population/place_population.hpp"

namespace bvc3d::config {

namespace {

const std::initializer_list<const char*> item_keys = {"name", "kind", "inputs", "recorded"};

// `kind k1=v1 k2=v2 …`: one line, no ": " (it sits in the model's canonical text).
template <class S>
std::string key_of(const std::string& kind, const S& s) {
    std::string key = kind;
    for (const auto& f : S::table().fields()) key += " " + f.key + "=" + params::to_text(f.get(s));
    return key;
}

template <class S>
std::vector<std::string> keys_of() {
    return S::table().keys();
}

}  // namespace

PopulationSpec head_direction_spec(const std::string& name, const HeadDirectionParams& p) {
    p.validate();
    PopulationSpec s;
    s.name = name;
    s.kind = "head-direction";
    s.key = key_of(s.kind, p);
    s.make = [p](const PopulationContext&) { return std::make_unique<HeadDirectionCells>(p); };
    s.footprint = [p](const std::vector<std::size_t>&) {
        return PopulationFootprint{p.space == HdSpace::spherical ? 20u : static_cast<std::size_t>(p.n), 0};
    };
    return s;
}

PopulationSpec grid_spec(const std::string& name, const GridParams& p) {
    p.validate();
    PopulationSpec s;
    s.name = name;
    s.kind = "grid";
    s.key = key_of(s.kind, p);
    s.make = [p](const PopulationContext& c) { return std::make_unique<GridCells>(p, c.seed); };
    s.footprint = [p](const std::vector<std::size_t>&) {
        return PopulationFootprint{static_cast<std::size_t>(p.n), 24.0 * p.n};  // each cell's orientation, phase
    };
    return s;
}

PopulationSpec growing_place_spec(const std::string& name, const PlaceParams& place, const GrowingParams& growing) {
    GrowingPlaceCells::check(place, growing);
    PopulationSpec s;
    s.name = name;
    s.kind = "growing-place";
    s.key = key_of(s.kind, growing) + key_of("", place);
    s.make = [place, growing](const PopulationContext& c) {
        if (c.input_sizes.size() != 1) throw InputError("a growing place-cell network reads one BVC population");
        return std::make_unique<GrowingPlaceCells>(static_cast<int>(c.input_sizes[0]), place, growing, c.seed);
    };
    // At its budget: a float weight per cell and input (the vector's doubling may hold up to twice that for a while).
    s.footprint = [growing](const std::vector<std::size_t>& in) {
        const auto n = static_cast<std::size_t>(growing.budget);
        return PopulationFootprint{n, 2.0 * 4.0 * static_cast<double>(n) * static_cast<double>(in.empty() ? 0 : in[0])};
    };
    return s;
}

PopulationSpec bvc_layer_spec(const std::string& name, const BvcParams& p) {
    p.validate();
    PopulationSpec s;
    s.name = name;
    s.kind = "bvc";
    s.key = key_of(s.kind, p);
    s.recorded = false;  // a BVC layer's rates are many; `recorded: true` keeps them
    s.make = [p](const PopulationContext& c) -> std::unique_ptr<Population> {
        if (!c.bvc_group) throw InputError("a BVC layer needs the model's source of returns");
        return std::make_unique<BvcPopulation>(c.bvc_group, c.bvc_group->add(p));
    };
    s.footprint = [p](const std::vector<std::size_t>&) {
        return PopulationFootprint{static_cast<std::size_t>(p.n_cells()), 0};
    };
    return s;
}

PopulationSpec adjacency_spec(const std::string& name, const AdjacencyParams& p, std::vector<std::string> inputs) {
    p.validate();
    PopulationSpec s;
    s.name = name;
    s.kind = "adjacency";
    s.inputs = std::move(inputs);
    s.recorded = false;  // it has no rates
    s.key = key_of(s.kind, p);
    s.make = [p](const PopulationContext& c) -> std::unique_ptr<Population> {
        if (c.input_sizes.size() != 2) throw InputError("an adjacency reads a place-cell and an HD population");
        if (c.input_sizes[1] != static_cast<std::size_t>(p.n_hd))
            throw InputError("an adjacency of n_hd " + std::to_string(p.n_hd) + " reads an HD population of " +
                             std::to_string(c.input_sizes[1]) + " cells");
        return std::make_unique<AdjacencyPopulation>(static_cast<int>(c.input_sizes[0]), p);
    };
    s.footprint = [p](const std::vector<std::size_t>& in) {
        return PopulationFootprint{0, HdAdjacency::bytes(in.empty() ? 0 : static_cast<int>(in[0]), p.n_hd)};
    };
    return s;
}

PopulationSpec reward_cells_spec(const std::string& name, const RewardCellParams& p, std::vector<std::string> inputs) {
    p.validate();
    PopulationSpec s;
    s.name = name;
    s.kind = "reward";
    s.inputs = std::move(inputs);
    s.recorded = false;  // their rates mean something once navigation has replayed
    s.key = key_of(s.kind, p);
    s.make = [p](const PopulationContext& c) -> std::unique_ptr<Population> {
        if (c.input_sizes.size() != 1) throw InputError("reward cells read one place-cell population");
        return std::make_unique<RewardCells>(c.input_sizes[0], p);
    };
    s.footprint = [p](const std::vector<std::size_t>& in) {
        return PopulationFootprint{p.n_goals(), 8.0 * double(p.n_goals()) * double(in.empty() ? 0 : in[0])};
    };
    return s;
}

namespace {

// A growing network's keys: its own and the place cells' dynamics (n_place aside: its cells are budget, n_initial).
PopulationSpec read_growing_place(const YamlView& v, const std::string& name) {
    if (v.has("n_place")) v["n_place"].fail("a growing network's cells are set by budget and n_initial");
    std::vector<std::string> item(item_keys.begin(), item_keys.end());
    auto with = [&item](std::vector<std::string> keys) {
        keys.insert(keys.end(), item.begin(), item.end());
        return keys;
    };
    GrowingParams growing;
    PlaceParams place;
    read_table(v, growing, GrowingParams::table(), with(keys_of<PlaceParams>()));
    read_table(v, place, PlaceParams::table(), with(keys_of<GrowingParams>()));
    check_at(v, [&] { GrowingPlaceCells::check(place, growing); });
    return growing_place_spec(name, place, growing);
}

std::vector<std::string> growing_place_keys() {
    auto keys = keys_of<GrowingParams>();
    for (const auto& k : keys_of<PlaceParams>())
        if (k != "n_place") keys.push_back(k);
    return keys;
}

}  // namespace

PopulationSpec grid_place_spec(const std::string& name, const PlaceParams& p, std::vector<std::string> inputs) {
    p.validate();
    PopulationSpec s;
    s.name = name;
    s.kind = "place";
    s.inputs = std::move(inputs);
    s.key = key_of(s.kind, p);
    // FNV-1a of the name: the networks of one trial draw different weights and masks.
    std::uint64_t tag = 14695981039346656037ull;
    for (unsigned char ch : name) tag = (tag ^ ch) * 1099511628211ull;
    s.make = [p, tag](const PopulationContext& c) -> std::unique_ptr<Population> {
        if (c.input_sizes.size() != 2) throw InputError("place cells read a BVC and a grid population");
        if (static_cast<double>(p.n_place) * static_cast<double>(c.input_sizes[0] + c.input_sizes[1]) > 1e9)
            throw InputError("n_place × (BVCs + grid cells) is more than 1e9 weights (4 GB)");
        return std::make_unique<PlacePopulation>(static_cast<int>(c.input_sizes[0]), p, hash_u64(c.seed, tag, 0),
                                                 static_cast<int>(c.input_sizes[1]));
    };
    // A float weight per cell and BVC, and a bit per cell and grid cell (the fixed mask).
    s.footprint = [p](const std::vector<std::size_t>& in) {
        const double bytes_per_cell = in.size() > 1 ? 4.0 * static_cast<double>(in[0]) + in[1] / 8.0 : 0;
        return PopulationFootprint{static_cast<std::size_t>(p.n_place), p.n_place * bytes_per_cell};
    };
    return s;
}

const std::vector<PopulationKind>& population_kinds() {
    static const std::vector<PopulationKind> kinds = {
        {"head-direction", "head-direction cells: cos(θ − θ_k), or the icosahedron's 20 for flying",
         keys_of<HeadDirectionParams>(), 0,
         [](const YamlView& v, const std::string& name, std::vector<std::string>) {
             HeadDirectionParams p;
             read_table(v, p, HeadDirectionParams::table(), item_keys);
             return head_direction_spec(name, p);
         }},
        {"grid", "grid cells: one module of the sum of three cosines, fed by the pose or path integration",
         keys_of<GridParams>(), 0,
         [](const YamlView& v, const std::string& name, std::vector<std::string>) {
             GridParams p;
             read_table(v, p, GridParams::table(), item_keys);
             return grid_spec(name, p);
         }},
        {"growing-place",
         "place cells that recruit a cell where none fires (weights from the BVC vector), up to a budget; Oja as §6",
         growing_place_keys(), 1,
         [](const YamlView& v, const std::string& name, std::vector<std::string>) {
             return read_growing_place(v, name);
         }},
        {"bvc", "a further BVC layer on the model's sensor (a scale of a multiscale model); not recorded by default",
         keys_of<BvcParams>(), 0,
         [](const YamlView& v, const std::string& name, std::vector<std::string>) {
             BvcParams p;
             read_table(v, p, BvcParams::table(), item_keys);
             return bvc_layer_spec(name, p);
         }},
        {"adjacency",
         "the HD-conditioned adjacency of place cells that navigation rolls forward (inputs: [place cells, HD cells]); "
         "no rates, its matrices kept",
         keys_of<AdjacencyParams>(), 2,
         [](const YamlView& v, const std::string& name, std::vector<std::string> inputs) {
             AdjacencyParams p;
             read_table(v, p, AdjacencyParams::table(), item_keys);
             return adjacency_spec(name, p, std::move(inputs));
         }},
        {"reward", "reward cells, one per goal, bound to the most active place cell near it (inputs: [place cells])",
         keys_of<RewardCellParams>(), 1,
         [](const YamlView& v, const std::string& name, std::vector<std::string> inputs) {
             RewardCellParams p;
             read_table(v, p, RewardCellParams::table(), item_keys);
             check_at(v, [&] { p.validate(); });
             return reward_cells_spec(name, p, std::move(inputs));
         }},
        {"place", "place cells fed by BVCs and grid cells (inputs: [a BVC population, a grid population])",
         keys_of<PlaceParams>(), 2,
         [](const YamlView& v, const std::string& name, std::vector<std::string> inputs) {
             PlaceParams p;
             read_table(v, p, PlaceParams::table(), item_keys);
             return grid_place_spec(name, p, std::move(inputs));
         }},
    };
    return kinds;
}

const PopulationKind* find_population_kind(const std::string& name) {
    for (const auto& k : population_kinds())
        if (k.name == name) return &k;
    return nullptr;
}

}  // namespace bvc3d::config

namespace bvc3d::config {

namespace {

// The names of `items`' inputs that lead back to item `start`, as "a → b → a", or "" when none does.
std::string cycle_through(std::size_t start, const std::vector<std::vector<std::size_t>>& reads,
                          const std::vector<std::string>& names) {
    std::vector<std::size_t> path{start};
    std::vector<char> seen(names.size(), 0);
    std::function<bool(std::size_t)> visit = [&](std::size_t i) {
        for (std::size_t j : reads[i]) {
            if (j == start) return true;
            if (seen[j]) continue;
            seen[j] = 1;
            path.push_back(j);
            if (visit(j)) return true;
            path.pop_back();
        }
        return false;
    };
    if (!visit(start)) return "";
    std::string text;
    for (std::size_t i : path) text += names[i] + " → ";
    return text + names[start];
}

// A population's parameters from its canonical key (`kind k1=v1 k2=[a, b]`, as a model's canonical text and
// `bvc3d config` write it), as a YAML mapping the kind reads.
YamlView parameters_of_key(const YamlView& key, const std::string& kind) {
    const std::string text = key.as_string();
    std::vector<std::string> tokens(1);
    int depth = 0;
    for (char ch : text) {
        depth += (ch == '[') - (ch == ']');
        if (ch == ' ' && depth == 0) tokens.emplace_back();
        else tokens.back() += ch;
    }
    if (tokens.front() != kind) key.fail("is the key of a '" + tokens.front() + "', not of a '" + kind + "'");
    std::string yaml = "{";
    for (std::size_t i = 1; i < tokens.size(); ++i) {
        const auto eq = tokens[i].find('=');
        if (eq == std::string::npos) key.fail("'" + tokens[i] + "' is not key=value");
        yaml += (i > 1 ? ", " : "") + tokens[i].substr(0, eq) + ": " + tokens[i].substr(eq + 1);
    }
    return YamlView::load_string(yaml + "}", key.file() + ": " + text);
}

}  // namespace

std::vector<PopulationSpec> populations_from_yaml(const YamlView& v) {
    if (!v.is_sequence()) v.fail("must be a list of populations (name, kind, inputs, parameters)");
    const std::size_t n = v.size();
    std::vector<std::string> names(n);
    for (std::size_t i = 0; i < n; ++i) {
        const YamlView item = v.at(i);
        if (!item.is_map()) item.fail("must be a mapping with name, kind, inputs and the kind's parameters");
        names[i] = item["name"].as_string();
        if (names[i].empty()) item["name"].fail("must not be empty");
        if (names[i] == "bvc" || names[i] == "place")
            item["name"].fail("'" + names[i] + "' is the model's own population; choose another name");
        for (std::size_t j = 0; j < i; ++j)
            if (names[j] == names[i]) item["name"].fail("'" + names[i] + "' names two populations");
    }
    // Inputs: each names a population; the reading graph has no cycle.
    std::vector<std::vector<std::string>> inputs(n);
    std::vector<std::vector<std::size_t>> reads(n);
    for (std::size_t i = 0; i < n; ++i) {
        const YamlView item = v.at(i);
        if (!item.has("inputs")) continue;
        const YamlView in = item["inputs"];
        if (!in.is_sequence()) in.fail("must be a list of population names");
        for (std::size_t k = 0; k < in.size(); ++k) {
            const std::string name = in.at(k).as_string();
            inputs[i].push_back(name);
            if (name == "bvc" || name == "place") continue;
            const auto it = std::find(names.begin(), names.end(), name);
            if (it == names.end()) {
                std::string known = "bvc, place";
                for (const std::string& other : names) known += ", " + other;
                in.at(k).fail("names no population '" + name + "' (the model has " + known + ")");
            }
            reads[i].push_back(static_cast<std::size_t>(it - names.begin()));
        }
    }
    for (std::size_t i = 0; i < n; ++i)
        if (const std::string cycle = cycle_through(i, reads, names); !cycle.empty())
            v.at(i)["inputs"].fail("populations read each other in a cycle: " + cycle);
    // Each by its kind.
    std::vector<PopulationSpec> specs(n);
    for (std::size_t i = 0; i < n; ++i) {
        const YamlView item = v.at(i);
        const std::string kind = item["kind"].as_string();
        const PopulationKind* k = find_population_kind(kind);
        if (!k) {
            std::string known;
            for (const auto& p : population_kinds()) known += (known.empty() ? "" : ", ") + p.name;
            item["kind"].fail("unknown population kind '" + kind + "' (known: " + known + ")");
        }
        if (inputs[i].size() != k->n_inputs)
            (item.has("inputs") ? item["inputs"] : item)
                .fail(kind + " reads " + std::to_string(k->n_inputs) + " population(s), got " +
                      std::to_string(inputs[i].size()));
        // Parameters as keys of the item, or (a model's canonical text read back) as its canonical key.
        specs[i] = item.has("key") ? k->read(parameters_of_key(item["key"], kind), names[i], inputs[i])
                                   : k->read(item, names[i], inputs[i]);
        specs[i].inputs = inputs[i];
        specs[i].recorded = item.get_bool("recorded", specs[i].recorded);
    }
    // In an order where each reads only those before it (file order among the free).
    std::vector<PopulationSpec> ordered;
    std::vector<char> placed(n, 0);
    while (ordered.size() < n)
        for (std::size_t i = 0; i < n; ++i) {
            if (placed[i]) continue;
            bool ready = true;
            for (std::size_t j : reads[i]) ready = ready && placed[j];
            if (!ready) continue;
            placed[i] = 1;
            ordered.push_back(std::move(specs[i]));
            break;
        }
    return ordered;
}

}  // namespace bvc3d::config

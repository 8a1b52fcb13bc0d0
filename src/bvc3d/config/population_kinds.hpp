#pragma once
// Config stage: the kinds of population a model's YAML may list (docs/model.md#populations), one list. Takes: a
// kind's name and its parameters. Gives: the PopulationSpec that makes it in a trial (config/population_spec.hpp).
//
// A model's `populations:` list (model_yaml.cpp) names each population, its kind, the populations it reads and its
// parameters (the keys of the kind's parameter table, beside name, kind, inputs and recorded).
#include <functional>
#include <string>
#include <vector>

#include "bvc3d/bvc/bvc_params.hpp"
#include "bvc3d/config/population_spec.hpp"
#include "bvc3d/config/yaml_reader.hpp"
#include "bvc3d/place/place_cell_network.hpp"
#include "bvc3d/population/grid_cells.hpp"
#include "bvc3d/population/growing_place_cells.hpp"
#include "bvc3d/population/hd_adjacency.hpp"
#include "bvc3d/population/head_direction_cells.hpp"
#include "bvc3d/population/reward_cells.hpp"

namespace bvc3d::config {

struct PopulationKind {
    std::string name;
    std::string doc;
    std::vector<std::string> keys;  // its parameters' keys (YAML)
    std::size_t n_inputs = 0;       // how many populations it reads
    // The spec of a population of this kind named `name` reading `inputs`, with the parameters of mapping `v` (its
    // other keys are the caller's: name, kind, inputs, recorded). InputError at the key on a bad value.
    std::function<PopulationSpec(const YamlView& v, const std::string& name, std::vector<std::string> inputs)> read;
};

const std::vector<PopulationKind>& population_kinds();
const PopulationKind* find_population_kind(const std::string& name);

// The specs of the kinds, for C++ callers.
PopulationSpec head_direction_spec(const std::string& name, const HeadDirectionParams& p);
PopulationSpec grid_spec(const std::string& name, const GridParams& p);
PopulationSpec growing_place_spec(const std::string& name, const PlaceParams& place, const GrowingParams& growing);
// A further BVC layer on the model's sensor (a scale of a multiscale model).
PopulationSpec bvc_layer_spec(const std::string& name, const BvcParams& p);
// Place cells reading `inputs` = {a BVC population, a grid population} (SPEC §16; place/place_cell_network.hpp).
// Their weights and mask come from the trial's seed hashed with `name`: each network draws its own.
PopulationSpec grid_place_spec(const std::string& name, const PlaceParams& p, std::vector<std::string> inputs);
// The HD-conditioned adjacency of navigation, reading `inputs` = {a place-cell population, an HD population of n_hd}.
PopulationSpec adjacency_spec(const std::string& name, const AdjacencyParams& p, std::vector<std::string> inputs);
// Reward cells, one per goal, reading `inputs` = {a place-cell population}.
PopulationSpec reward_cells_spec(const std::string& name, const RewardCellParams& p, std::vector<std::string> inputs);

}  // namespace bvc3d::config

namespace bvc3d::config {

// A model's `populations:` sequence: each item's name (unique; not "bvc" or "place", the model's own), kind (of
// population_kinds()), inputs (names of "bvc", "place" or items of the list) and recorded (default true), and its
// kind's parameters. Returned in an order where each reads only those before it. InputError at the key: unknown
// kinds, duplicate names, inputs that name no population, cycles, a count of inputs the kind does not take.
std::vector<PopulationSpec> populations_from_yaml(const YamlView& v);

}  // namespace bvc3d::config

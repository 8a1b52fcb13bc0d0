#pragma once
// Config stage: a whole model — which scanner it reads, its BVC layer and its place-cell network —
// and the named presets: the paper's four (Table I), the authors'-code 2-D baseline
// (docs/model-reference.md#presets) and the flying agents' three (docs/flying.md#models).
#include <functional>
#include <string>
#include <vector>

#include "bvc3d/bvc/boundary_vector_layer.hpp"
#include "bvc3d/config/population_spec.hpp"
#include "bvc3d/place/place_cell_network.hpp"
#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d {

struct ModelSpec {
    std::string name;
    LidarSpec sensor;
    BvcParams bvc;
    PlaceParams place;
    // Populations besides the BVC layer ("bvc") and the place cells ("place"), in the order they are made.
    std::vector<PopulationSpec> populations;
    // The grid population of `populations` the place cells also read (SPEC §16), or "" (the paper's: BVCs only).
    std::string place_grid;
    static constexpr double max_weights = 1e9;  // n_place × BVCs (4 GB of float weights)
    void validate() const;
    // The model's scales of place cells, by population name: its own ("place"), then each population of kind
    // "place" (a multiscale model's further scales, SPEC §16) in the order of `populations`. The multiscale
    // analysis fuses them; navigation learns an adjacency and reward cells on each.
    std::vector<std::string> place_scales() const;
};

struct ModelPreset {
    std::string name;
    std::string description;
    std::function<ModelSpec()> make;
    bool flying = false;  // made for flying agents (fly-*): the ground robot refuses it, and they refuse the others
};

// The one list of model presets, in the order help texts show them.
const std::vector<ModelPreset>& model_presets();
std::vector<std::string> model_preset_names();
ModelSpec model_preset(const std::string& name);                // throws InputError for unknown names
const ModelPreset* find_model_preset(const std::string& name);  // nullptr for unknown names

}  // namespace bvc3d

#pragma once
// Config stage: a population of a model beyond its BVC layer and place cells (population/population.hpp): its name,
// the populations it reads, and how to make it. Takes: what its kind needs. Gives: the spec a ModelSpec holds, its
// canonical text (in the model's, hence in fingerprints) and, per trial, the population itself.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "bvc3d/bvc/bvc_group.hpp"
#include "bvc3d/population/population.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

// What a spec's `make` is given.
struct PopulationContext {
    std::uint64_t seed = 0;                // the trial's
    std::vector<std::size_t> input_sizes;  // cells of each population it reads, in the order of `inputs`
    const World* world = nullptr;          // null for a trial without one
    // The BVC layers of the model's source (its "bvc" is one): a population that is a BVC layer adds its own.
    std::shared_ptr<BvcLayerGroup> bvc_group;
};

// What a population holds, for the memory check before a run: its cells (each recorded sample keeps one float per
// cell) and the bytes of its state (weights and the like) at their largest.
struct PopulationFootprint {
    std::size_t cells = 0;
    double state_bytes = 0;
};

struct PopulationSpec {
    std::string name;                 // unique in its model; "bvc" and "place" name the model's own
    std::string kind;                 // for messages and tables
    std::vector<std::string> inputs;  // the populations of the same model it reads, by name
    bool recorded = true;             // its rates are recorded at the sampling steps (and analysed)
    // Canonical text of everything that changes its results (its kind and parameters): part of the model's.
    std::string key;
    std::function<std::unique_ptr<Population>(const PopulationContext&)> make;
    // Its footprint for the cells of the populations it reads (in the order of `inputs`).
    std::function<PopulationFootprint(const std::vector<std::size_t>& input_sizes)> footprint;
};

}  // namespace bvc3d

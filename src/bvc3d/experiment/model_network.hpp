#pragma once
// Experiment stage: the populations of a trial group's models, built from their configurations. Takes: the trials of
// a group (one model each) and where their returns come from. Gives: one PopulationNetwork with every model's BVC
// layer ("bvc"), place cells ("place", reading "bvc") and other populations (ModelSpec::populations), and each
// model's records (recorder/trial_record.hpp) from it.
//
// Models whose sensors are the same beam table (or that a SourceFactory gives the same source) read one source: its
// BVC layers form one group (bvc/bvc_group.hpp), which reads it once a step.
#include <memory>
#include <vector>

#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/population/population_network.hpp"
#include "bvc3d/recorder/trial_record.hpp"
#include "bvc3d/sensor/return_source.hpp"

namespace bvc3d {

struct ModelNetwork {
    // Place-cell steps wait until this many are due; then each network takes them at once, reading its weights once
    // for every 8 steps. A closed loop (navigation) steps with block 1 and reads each step's rates at once.
    static constexpr std::size_t block_steps = 16;
    // InputError naming the model and population for inputs that name no population of its model, cycles, ...
    ModelNetwork(const World* world, const std::vector<TrialConfig>& trials, const SourceFactory& factory,
                 bool record_bvc, std::size_t block = block_steps);

    PopulationNetwork network;
    // Per model: the nodes of its BVC layer, its place cells, and its other populations.
    struct Nodes {
        std::size_t bvc, place;
        std::vector<std::size_t> others;
    };
    std::vector<Nodes> nodes;

    // Each model's records of the samples from `from` on; with `final`, what each population keeps at the end
    // (the weights), and the rates moved out of the network rather than copied.
    std::vector<ModelRecord> records(std::size_t from, bool final = false);
    // Sets back the recorded samples and every population's state of a checkpoint; InputError if they do not fit
    // (the network is then unusable: the caller starts from a new one).
    void restore(const std::vector<ModelRecord>& recorded, const std::vector<std::vector<StateArray>>& states);
};

}  // namespace bvc3d

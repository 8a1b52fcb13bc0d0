#pragma once
// Population stage: the populations of a trial group (every model's) with their declared inputs, stepped as the
// agent steps. Takes: populations, each naming the populations it reads, and the model steps. Gives: each
// population's rates at the recorded steps, its state, and what it keeps at the end.
//
// Populations that read a step's returns (each_step) are stepped as the step happens; the others wait until
// `block` steps are due, then each takes them at once, in an order where every population comes after those it
// reads (a place-cell network reads its weights once for every 8 steps: with four models' weights, more than an L2
// cache holds, that matters). A step's results do not depend on the block: only the timing changes.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bvc3d/population/population.hpp"

namespace bvc3d {

struct PopulationNode {
    std::string name;  // for messages: unique in the network
    std::unique_ptr<Population> population;
    std::vector<std::size_t> inputs;  // the nodes it reads (indices into the network's nodes)
    bool recorded = false;            // its rates are kept at the recording steps
};

class PopulationNetwork {
public:
    // InputError naming the node for an input that does not exist, a cycle, or an each-step population that reads
    // another population. `block` (>= 1): steps per block.
    PopulationNetwork(std::vector<PopulationNode> nodes, std::size_t block);

    std::size_t size() const { return nodes_.size(); }
    const PopulationNode& node(std::size_t i) const { return nodes_[i]; }

    // Model step `index`; the rates of each recorded node are kept if `record`.
    void step(const ModelStep& s, std::int64_t index, bool learn, bool record);
    void flush();  // steps the waiting steps now (before a checkpoint, and at the end)
    // Node i's rates at the last step flushed (its size; empty before the first): a closed loop steps with block 1
    // and reads each step's rates here.
    std::span<const double> latest(std::size_t i) const { return latest_[i]; }
    // The kept rates of a recorded node (recorded steps × its size, float32 as trial files store them).
    std::vector<float>& recorded(std::size_t i) { return recorded_[i]; }
    void reserve(std::size_t samples);  // room for this many recorded steps

    // Every node's state, in node order (flushed first), and setting it back.
    std::vector<std::vector<StateArray>> state();
    void restore(const std::vector<std::vector<StateArray>>& states);
    // The sum of each counter over the nodes.
    std::vector<std::pair<std::string, std::int64_t>> counters() const;

private:
    std::vector<PopulationNode> nodes_;
    std::vector<std::size_t> order_;  // blocked nodes, each after those it reads
    std::size_t block_;
    std::vector<ModelStep> steps_;  // the due steps
    std::vector<char> learn_, record_;
    std::int64_t first_index_ = 0;
    std::vector<std::vector<double>> due_;  // per node: its rates for the due steps
    std::vector<std::vector<float>> recorded_;
    std::vector<std::vector<double>> latest_;  // per node: its rates at the last step flushed
    void step_node(std::size_t i, const StepBlock& block, std::size_t from);
};

}  // namespace bvc3d

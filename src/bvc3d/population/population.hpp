#pragma once
// Population stage: the seam through which kinds of cells enter a model (docs/architecture.md#populations).
// Takes: the agent's model steps and the rates of the populations a population reads. Gives: its rates, step by
// step, and its state as named arrays (for checkpoints, and what a trial keeps at its end).
//
// A model is a network of populations with declared inputs (population_network.hpp): today a BVC layer, which reads
// a sensor's returns, and a place-cell network, which reads the BVC layer. The trial runner, the recorder and the
// analysis see only this interface: a new kind of cell is a Population, the PopulationSpec that makes it
// (config/population_spec.hpp) and a test.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "bvc3d/agent/agent.hpp"

namespace bvc3d {

// Consecutive model steps, stepped together: the agent's steps, and for each whether learning is on.
struct StepBlock {
    std::span<const ModelStep> steps;
    std::span<const char> learn;
    std::int64_t first_index = 0;  // the first step's index in the trial (a source reads its returns by it)
    std::size_t size() const { return steps.size(); }
};

// A named array of a population's state, row-major with its shape.
struct StateArray {
    std::string name;
    std::vector<std::size_t> shape;
    std::variant<std::vector<float>, std::vector<double>> values;
    std::size_t count() const {
        return std::visit([](const auto& v) { return v.size(); }, values);
    }
};
// The array named `name` of `arrays` (InputError if missing or of another type or size).
const std::vector<float>& state_floats(const std::vector<StateArray>& arrays, const std::string& name,
                                       std::size_t count);
const std::vector<double>& state_doubles(const std::vector<StateArray>& arrays, const std::string& name,
                                         std::size_t count);

class Population {
public:
    virtual ~Population() = default;
    virtual std::size_t size() const = 0;  // cells
    // True for a population that reads what exists only at its step (a sensor's returns): it is stepped one step
    // at a time, as the step happens, and reads no other population. The others are stepped in blocks of steps
    // (their weights then stay in cache), after the populations they read.
    virtual bool each_step() const { return false; }
    // The rates of the block's steps into `out` (steps × size, row-major); inputs[i] holds the rates of the i-th
    // population this one reads, for the same steps (steps × its size).
    virtual void step(const StepBlock& block, std::span<const std::span<const double>> inputs,
                      std::span<double> out) = 0;
    // Everything a checkpoint needs to continue exactly, and setting it back (InputError if it does not fit).
    virtual std::vector<StateArray> state() const { return {}; }
    virtual void restore(const std::vector<StateArray>&) {}
    // Back to rest for a new episode (navigation's next start): activity cleared, what was learned kept. The
    // default: nothing to clear (a population whose rates follow from its inputs alone).
    virtual void reset_activity() {}
    // What a trial keeps of the population at its end (a network's weights).
    virtual std::vector<StateArray> kept() const { return {}; }
    // Counts a trial reports (name, count), e.g. the BVC layer's full-scan fallbacks.
    virtual std::vector<std::pair<std::string, std::int64_t>> counters() const { return {}; }
};

}  // namespace bvc3d

#include "bvc3d/population/population_network.hpp"

#include <algorithm>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

namespace {
template <class T>
const std::vector<T>& state_values(const std::vector<StateArray>& arrays, const std::string& name, std::size_t count) {
    for (const StateArray& a : arrays)
        if (a.name == name) {
            const auto* v = std::get_if<std::vector<T>>(&a.values);
            if (!v || v->size() != count)
                throw InputError("state array '" + name + "' has the wrong type or size (" + std::to_string(a.count()) +
                                 " values for " + std::to_string(count) + ")");
            return *v;
        }
    throw InputError("state array '" + name + "' is missing");
}
}  // namespace

const std::vector<float>& state_floats(const std::vector<StateArray>& arrays, const std::string& name,
                                       std::size_t count) {
    return state_values<float>(arrays, name, count);
}
const std::vector<double>& state_doubles(const std::vector<StateArray>& arrays, const std::string& name,
                                         std::size_t count) {
    return state_values<double>(arrays, name, count);
}

PopulationNetwork::PopulationNetwork(std::vector<PopulationNode> nodes, std::size_t block)
    : nodes_(std::move(nodes)), block_(std::max<std::size_t>(block, 1)) {
    const std::size_t n = nodes_.size();
    for (const PopulationNode& node : nodes_) {
        if (!node.population) throw InputError("population '" + node.name + "' was not made");
        for (std::size_t in : node.inputs)
            if (in >= n) throw InputError("population '" + node.name + "' reads a population that does not exist");
        if (node.population->each_step() && !node.inputs.empty())
            throw InputError("population '" + node.name + "' reads each step's returns and cannot read '" +
                             nodes_[node.inputs.front()].name + "' too");
    }
    // Blocked nodes in an order where each comes after those it reads (Kahn's algorithm, stable).
    std::vector<char> placed(n, 0);
    for (std::size_t i = 0; i < n; ++i) placed[i] = nodes_[i].population->each_step();
    for (bool progress = true; progress;) {
        progress = false;
        for (std::size_t i = 0; i < n; ++i) {
            if (placed[i]) continue;
            const auto& in = nodes_[i].inputs;
            if (std::all_of(in.begin(), in.end(), [&](std::size_t j) { return placed[j] != 0; })) {
                placed[i] = 1;
                order_.push_back(i);
                progress = true;
            }
        }
    }
    for (std::size_t i = 0; i < n; ++i)
        if (!placed[i]) throw InputError("population '" + nodes_[i].name + "' is in a cycle of inputs");
    due_.resize(n);
    recorded_.resize(n);
    latest_.resize(n);
    for (std::size_t i = 0; i < n; ++i) due_[i].reserve(block_ * nodes_[i].population->size());
}

void PopulationNetwork::reserve(std::size_t samples) {
    for (std::size_t i = 0; i < nodes_.size(); ++i)
        if (nodes_[i].recorded) recorded_[i].reserve(samples * nodes_[i].population->size());
}

void PopulationNetwork::step_node(std::size_t i, const StepBlock& block, std::size_t from) {
    const std::size_t size = nodes_[i].population->size();
    std::vector<std::span<const double>> inputs;
    inputs.reserve(nodes_[i].inputs.size());
    for (std::size_t j : nodes_[i].inputs) {
        const std::size_t width = nodes_[j].population->size();
        inputs.emplace_back(due_[j].data() + from * width, block.size() * width);
    }
    due_[i].resize((from + block.size()) * size);
    nodes_[i].population->step(block, inputs, std::span<double>(due_[i]).subspan(from * size, block.size() * size));
}

void PopulationNetwork::step(const ModelStep& s, std::int64_t index, bool learn, bool record) {
    if (steps_.empty()) first_index_ = index;
    steps_.push_back(s);
    learn_.push_back(learn);
    record_.push_back(record);
    const std::size_t k = steps_.size() - 1;
    const StepBlock now{std::span<const ModelStep>(steps_).subspan(k, 1), std::span<const char>(learn_).subspan(k, 1),
                        index};
    for (std::size_t i = 0; i < nodes_.size(); ++i)
        if (nodes_[i].population->each_step()) step_node(i, now, k);
    if (steps_.size() >= block_) flush();
}

void PopulationNetwork::flush() {
    if (steps_.empty()) return;
    const StepBlock block{steps_, learn_, first_index_};
    for (std::size_t i : order_) step_node(i, block, 0);
    for (std::size_t i = 0; i < nodes_.size(); ++i) {
        if (nodes_[i].recorded) {
            const std::size_t size = nodes_[i].population->size();
            for (std::size_t k = 0; k < steps_.size(); ++k)
                if (record_[k])
                    for (std::size_t c = 0; c < size; ++c)
                        recorded_[i].push_back(static_cast<float>(due_[i][k * size + c]));
        }
        const std::size_t size = nodes_[i].population->size();
        latest_[i].assign(due_[i].end() - static_cast<std::ptrdiff_t>(size), due_[i].end());
        due_[i].clear();
    }
    steps_.clear();
    learn_.clear();
    record_.clear();
}

std::vector<std::vector<StateArray>> PopulationNetwork::state() {
    flush();
    std::vector<std::vector<StateArray>> out;
    for (const PopulationNode& node : nodes_) out.push_back(node.population->state());
    return out;
}

void PopulationNetwork::restore(const std::vector<std::vector<StateArray>>& states) {
    if (states.size() != nodes_.size())
        throw InputError("it holds " + std::to_string(states.size()) + " populations, not " +
                         std::to_string(nodes_.size()));
    for (std::size_t i = 0; i < nodes_.size(); ++i) nodes_[i].population->restore(states[i]);
}

std::vector<std::pair<std::string, std::int64_t>> PopulationNetwork::counters() const {
    std::vector<std::pair<std::string, std::int64_t>> sum;
    for (const PopulationNode& node : nodes_)
        for (const auto& counter : node.population->counters()) {
            auto at = std::find_if(sum.begin(), sum.end(), [&](const auto& c) { return c.first == counter.first; });
            if (at == sum.end()) sum.push_back(counter);
            else at->second += counter.second;
        }
    return sum;
}

}  // namespace bvc3d

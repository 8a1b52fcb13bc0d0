#include "bvc3d/experiment/model_network.hpp"

#include <algorithm>

#include "bvc3d/bvc/bvc_group.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/population/bvc_population.hpp"
#include "bvc3d/population/place_population.hpp"

namespace bvc3d {

namespace {

struct Built {
    std::vector<PopulationNode> nodes;
    std::vector<ModelNetwork::Nodes> wiring;
};

// The BVC layer groups of a group of trials: one per source of returns.
class Groups {
public:
    Groups(const World* world, std::uint64_t seed, const SourceFactory& factory)
        : world_(world), seed_(seed), factory_(factory) {}
    std::shared_ptr<BvcLayerGroup> of(const ModelSpec& model) {
        std::shared_ptr<ReturnSource> made = factory_ ? factory_(model, world_) : nullptr;
        for (const auto& g : groups_) {
            const LidarSpec* table = g->source()->beam_table();
            if (made ? g->source() == made : table && table->same_beams(model.sensor)) return g;
        }
        if (!made) {
            if (!world_)
                throw InputError("model '" + model.name +
                                 "' has no source of returns: without a world its sensor cannot be cast");
            // Sensor noise: the trial's own stream, the same draws for every sensor of the group (common random
            // numbers: conditions that differ in their noise level see the same underlying draws).
            const std::uint64_t noise_seed = hash_u64(seed_, static_cast<std::uint64_t>(Stream::sensor_noise), 0);
            made = std::make_shared<RayCastSource>(*world_, model.sensor, noise_seed);
        }
        return groups_.emplace_back(std::make_shared<BvcLayerGroup>(made));
    }

private:
    const World* world_;
    std::uint64_t seed_;
    const SourceFactory& factory_;
    std::vector<std::shared_ptr<BvcLayerGroup>> groups_;
};

// Model i's own populations ("bvc", "place") and its others, wired by name within the model.
void add_model(Built& b, Groups& groups, const TrialConfig& c, std::size_t i, const World* world, bool record_bvc) {
    const std::string prefix = "model " + std::to_string(i) + " ('" + c.model.name + "'): ";
    ModelNetwork::Nodes wiring;
    const auto group = groups.of(c.model);
    const std::size_t layer = group->add(c.model.bvc);
    wiring.bvc = b.nodes.size();
    b.nodes.push_back({prefix + "bvc", std::make_unique<BvcPopulation>(group, layer), {}, record_bvc});
    wiring.place = b.nodes.size();
    b.nodes.push_back({prefix + "place", nullptr, {wiring.bvc}, true});
    // The others, by name: each may read "bvc", "place" or another of the model's populations listed before it.
    std::vector<std::pair<std::string, std::size_t>> named{{"bvc", wiring.bvc}, {"place", wiring.place}};
    const std::size_t first = b.nodes.size();
    for (const PopulationSpec& spec : c.model.populations) {
        if (std::any_of(named.begin(), named.end(), [&](const auto& n) { return n.first == spec.name; }))
            throw InputError(prefix + "population '" + spec.name + "': the name is taken");
        wiring.others.push_back(first + wiring.others.size());
        named.emplace_back(spec.name, wiring.others.back());
    }
    const auto node_of = [&](const std::string& name) {
        const auto at = std::find_if(named.begin(), named.end(), [&](const auto& n) { return n.first == name; });
        return at == named.end() ? b.nodes.size() : at->second;
    };
    for (const PopulationSpec& spec : c.model.populations) {
        std::vector<std::size_t> inputs;
        for (const std::string& input : spec.inputs) {
            const std::size_t at = node_of(input);
            if (at == b.nodes.size())
                throw InputError(prefix + "population '" + spec.name + "' reads '" + input +
                                 "', which names no population of the model");
            inputs.push_back(at);
        }
        b.nodes.push_back({prefix + spec.name, nullptr, inputs, spec.recorded});
    }
    // The place cells: made once what they read is (their grid population, when they read one).
    std::size_t grid = b.nodes.size();
    if (!c.model.place_grid.empty()) {
        grid = node_of(c.model.place_grid);
        if (grid == b.nodes.size() || grid == wiring.bvc || grid == wiring.place)
            throw InputError(prefix + "place_grid '" + c.model.place_grid + "' names no population of the model");
        b.nodes[wiring.place].inputs.push_back(grid);
    }
    const auto make_place = [&] {
        if (b.nodes[wiring.place].population) return;
        int n_grid = 0;
        if (grid < b.nodes.size()) {
            if (!b.nodes[grid].population)
                throw InputError(prefix + "the place cells read '" + c.model.place_grid +
                                 "', made after a population that reads them: list it first");
            n_grid = static_cast<int>(b.nodes[grid].population->size());
        }
        auto place = std::make_unique<PlacePopulation>(c.model.bvc.n_cells(), c.model.place, c.seed, n_grid);
        if (c.weights) place->network().set_weights(c.weights->values);
        b.nodes[wiring.place].population = std::move(place);
    };
    if (c.model.place_grid.empty()) make_place();
    // Made in order, each knowing the sizes of its inputs.
    for (std::size_t k = 0; k < c.model.populations.size(); ++k) {
        const PopulationSpec& spec = c.model.populations[k];
        PopulationNode& node = b.nodes[wiring.others[k]];
        PopulationContext context{c.seed, {}, world, group};
        for (std::size_t in : node.inputs) {
            if (in == wiring.place) make_place();
            if (!b.nodes[in].population)
                throw InputError(prefix + "population '" + spec.name + "' reads a population made after it: list '" +
                                 b.nodes[in].name + "' first");
            context.input_sizes.push_back(b.nodes[in].population->size());
        }
        node.population = spec.make(context);
        if (!node.population) throw InputError(prefix + "population '" + spec.name + "' could not be made");
    }
    make_place();
    b.wiring.push_back(std::move(wiring));
}

Built build(const World* world, const std::vector<TrialConfig>& trials, const SourceFactory& factory, bool record_bvc) {
    Built b;
    Groups groups(world, trials.front().seed, factory);
    for (std::size_t i = 0; i < trials.size(); ++i) add_model(b, groups, trials[i], i, world, record_bvc);
    return b;
}

}  // namespace

ModelNetwork::ModelNetwork(const World* world, const std::vector<TrialConfig>& trials, const SourceFactory& factory,
                           bool record_bvc, std::size_t block)
    : network({}, 1) {
    Built b = build(world, trials, factory, record_bvc);
    nodes = std::move(b.wiring);
    network = PopulationNetwork(std::move(b.nodes), block);
}

std::vector<ModelRecord> ModelNetwork::records(std::size_t from, bool final) {
    auto take = [&](std::size_t node) {
        std::vector<float>& all = network.recorded(node);
        const std::size_t start = from * network.node(node).population->size();
        if (final && from == 0) return std::move(all);
        return std::vector<float>(all.begin() + static_cast<std::ptrdiff_t>(std::min(start, all.size())), all.end());
    };
    std::vector<ModelRecord> out;
    for (const Nodes& n : nodes) {
        ModelRecord rec;
        const Population& place = *network.node(n.place).population;
        rec.n_place = static_cast<int>(place.size());
        rec.n_bvc = static_cast<int>(network.node(n.bvc).population->size());
        rec.rates = take(n.place);
        rec.bvc = take(n.bvc);
        if (final) rec.weights = state_floats(place.kept(), "weights", place.size() * rec.n_bvc);
        for (std::size_t j : n.others) {
            const PopulationNode& node = network.node(j);
            PopulationRecord p;
            p.name = node.name.substr(node.name.rfind(": ") + 2);
            p.cells = node.population->size();
            p.recorded = node.recorded;
            p.rates = take(j);
            if (final) p.kept = node.population->kept();
            rec.populations.push_back(std::move(p));
        }
        out.push_back(std::move(rec));
    }
    return out;
}

void ModelNetwork::restore(const std::vector<ModelRecord>& recorded,
                           const std::vector<std::vector<StateArray>>& states) {
    const auto mismatch = [] { throw InputError("its arrays do not match the group's models"); };
    if (recorded.size() != nodes.size()) mismatch();
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        const ModelRecord& m = recorded[i];
        if (m.n_place != static_cast<int>(network.node(nodes[i].place).population->size()) ||
            m.n_bvc != static_cast<int>(network.node(nodes[i].bvc).population->size()) ||
            m.populations.size() != nodes[i].others.size())
            mismatch();
        for (std::size_t k = 0; k < m.populations.size(); ++k)
            if (m.populations[k].cells != network.node(nodes[i].others[k]).population->size()) mismatch();
    }
    network.restore(states);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
        network.recorded(nodes[i].place) = recorded[i].rates;
        network.recorded(nodes[i].bvc) = recorded[i].bvc;
        for (std::size_t k = 0; k < nodes[i].others.size(); ++k)
            network.recorded(nodes[i].others[k]) = recorded[i].populations[k].rates;
    }
}

}  // namespace bvc3d

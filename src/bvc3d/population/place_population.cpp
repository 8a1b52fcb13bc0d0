#include "bvc3d/population/place_population.hpp"

#include <cmath>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

void PlacePopulation::step(const StepBlock& block, std::span<const std::span<const double>> inputs,
                           std::span<double> out) {
    const std::size_t expected = net_.n_grid() > 0 ? 2 : 1;
    if (inputs.size() != expected)
        throw InputError(net_.n_grid() > 0 ? "place cells fed by grid cells read a BVC and a grid population"
                                           : "a place-cell network reads one BVC population");
    const auto v = net_.step_block(inputs[0], expected == 2 ? inputs[1] : std::span<const double>{}, block.learn);
    std::copy(v.begin(), v.end(), out.begin());  // float rates, exactly
}

std::vector<StateArray> PlacePopulation::state() const {
    const std::size_t n = size();
    auto kept_arrays = kept();
    kept_arrays.push_back({"membrane", {n}, std::vector<float>(net_.membrane().begin(), net_.membrane().end())});
    kept_arrays.push_back({"rates", {n}, std::vector<float>(net_.rates().begin(), net_.rates().end())});
    return kept_arrays;
}

void PlacePopulation::restore(const std::vector<StateArray>& state) {
    // Everything is checked before anything changes.
    const std::size_t n = size(), b = static_cast<std::size_t>(net_.n_bvc());
    const auto& weights = state_floats(state, "weights", n * b);
    const auto& membrane = state_floats(state, "membrane", n);
    const auto& rates = state_floats(state, "rates", n);
    for (float w : weights)
        if (!std::isfinite(w)) throw InputError("its weights are not finite");
    net_.set_weights(weights);
    net_.set_state(membrane, rates);
}

std::vector<StateArray> PlacePopulation::kept() const {
    return {{"weights", {size(), static_cast<std::size_t>(net_.n_bvc())}, net_.weights()}};
}

}  // namespace bvc3d

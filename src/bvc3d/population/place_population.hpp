#pragma once
// Population stage: the paper's place-cell network (place/place_cell_network.hpp) as a population. Takes: the rates
// of one BVC population, and with n_grid > 0 those of a grid-cell population (the second input). Gives: place-cell
// rates, learning with Oja's rule on the steps that learn; keeps its weights (n_place × n_bvc) at the end of a trial.
#include <cstdint>
#include <span>

#include "bvc3d/place/place_cell_network.hpp"
#include "bvc3d/population/population.hpp"

namespace bvc3d {

class PlacePopulation : public Population {
public:
    PlacePopulation(int n_bvc, const PlaceParams& params, std::uint64_t seed, int n_grid = 0)
        : net_(n_bvc, params, seed, n_grid) {}
    PlaceCellNetwork& network() { return net_; }

    std::size_t size() const override { return static_cast<std::size_t>(net_.n_place()); }
    void step(const StepBlock& block, std::span<const std::span<const double>> inputs, std::span<double> out) override;
    std::vector<StateArray> state() const override;
    void restore(const std::vector<StateArray>& state) override;
    std::vector<StateArray> kept() const override;
    void reset_activity() override { net_.reset(); }

private:
    PlaceCellNetwork net_;
};

}  // namespace bvc3d

#pragma once
// Population stage: a BVC layer as a population. Takes: each step's pose (its returns come from the layer's group,
// bvc/bvc_group.hpp, which reads the source once a step for every layer on it). Gives: the layer's rates.
#include <memory>

#include "bvc3d/bvc/bvc_group.hpp"
#include "bvc3d/population/population.hpp"

namespace bvc3d {

class BvcPopulation : public Population {
public:
    BvcPopulation(std::shared_ptr<BvcLayerGroup> group, std::size_t layer) : group_(std::move(group)), layer_(layer) {}
    std::size_t size() const override { return group_->layer(layer_).n_cells(); }
    bool each_step() const override { return true; }
    void step(const StepBlock& block, std::span<const std::span<const double>>, std::span<double> out) override {
        const std::size_t n = size();
        for (std::size_t k = 0; k < block.size(); ++k)
            group_->rates(block.first_index + static_cast<std::int64_t>(k), block.steps[k].pose, layer_,
                          out.subspan(k * n, n));
    }
    std::vector<std::pair<std::string, std::int64_t>> counters() const override {
        return {{"full_scan_fallbacks", group_->full_scan_fallbacks(layer_)}};
    }

private:
    std::shared_ptr<BvcLayerGroup> group_;
    std::size_t layer_;
};

}  // namespace bvc3d

#include "bvc3d/bvc/bvc_group.hpp"

#include <algorithm>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

BvcLayerGroup::BvcLayerGroup(std::shared_ptr<ReturnSource> source) : source_(std::move(source)) {
    if (!source_) throw InputError("BVC layer group: no source of returns");
}

std::size_t BvcLayerGroup::add(const BvcParams& params) {
    if (planned_) throw InputError("BVC layer group: a layer added after the first step");
    layers_.emplace_back(params);
    rates_.emplace_back(layers_.back().n_cells());
    fallbacks_.push_back(0);
    return layers_.size() - 1;
}

void BvcLayerGroup::plan() {
    planned_ = true;
    const LidarSpec* table = source_->beam_table();
    rows_.assign(table ? table->elevations.size() : 0, 0);
    for (const BoundaryVectorLayer& layer : layers_) {
        plans_.push_back(table ? layer.plan(*table) : ScanPlan{});
        for (std::size_t r = 0; r < plans_.back().rows.size(); ++r) rows_[r] |= plans_.back().rows[r];
    }
    shared_of_.assign(layers_.size(), -1);
    if (!table) return;
    // Layers that differ only in their elevations, each group summing the union of them once.
    for (std::size_t i = 0; i < layers_.size(); ++i) {
        auto same = std::find_if(shared_.begin(), shared_.end(), [&](const SharedSums& g) {
            return layers_[i].can_share_sums(layers_[g.layers.front()].params());
        });
        if (same == shared_.end()) same = shared_.insert(shared_.end(), SharedSums{});
        same->layers.push_back(i);
    }
    for (SharedSums& g : shared_) {
        BvcParams all = layers_[g.layers.front()].params();
        for (std::size_t i : g.layers)
            for (double psi : layers_[i].params().elevations)
                if (std::find(all.elevations.begin(), all.elevations.end(), psi) == all.elevations.end())
                    all.elevations.push_back(psi);
        // Alone, or too many layers to sum at once: each sums its own.
        if (g.layers.size() < 2 ||
            static_cast<double>(all.elevations.size()) * all.n_dir * all.n_per_axis > BvcParams::max_cells)
            continue;
        g.layer = std::make_unique<BoundaryVectorLayer>(all);
        g.plan = g.layer->plan(*table);
    }
    std::erase_if(shared_, [](const SharedSums& g) { return !g.layer; });
    for (std::size_t u = 0; u < shared_.size(); ++u)
        for (std::size_t i : shared_[u].layers) shared_of_[i] = static_cast<int>(u);
}

void BvcLayerGroup::rates(std::int64_t step, const Pose& pose, std::size_t i, std::span<double> out) {
    if (step != step_) this->step(step, pose);
    std::copy(rates_[i].begin(), rates_[i].end(), out.begin());
}

void BvcLayerGroup::step(std::int64_t step, const Pose& pose) {
    if (!planned_) plan();
    static const std::vector<char> all_rows;
    step_ = step;
    source_->returns(static_cast<std::uint64_t>(step), pose, pose.level() ? rows_ : all_rows, scan_);
    full_read_ = false;
    if (pose.level())
        for (const SharedSums& g : shared_) g.layer->sum_pruned(scan_, g.plan);
    for (std::size_t i = 0; i < layers_.size(); ++i)
        if (!layer_rates(i, step, pose)) ++fallbacks_[i];
}

// Layer i's rates from this step's returns. A scan cast with a plan's rows whose bound fails is read again in full
// and summed exactly; returns false then.
bool BvcLayerGroup::layer_rates(std::size_t i, std::int64_t step, const Pose& pose) {
    const bool planned = source_->beam_table() && pose.level();
    if (planned && (shared_of_[i] < 0
                        ? layers_[i].rates_pruned(scan_, plans_[i], rates_[i])
                        : layers_[i].rates_pruned_shared(scan_, plans_[i], *shared_[shared_of_[i]].layer, rates_[i])))
        return true;
    if (!planned) {
        layers_[i].rates(scan_, rates_[i]);  // every return was read
        return true;
    }
    if (!full_read_) source_->returns(static_cast<std::uint64_t>(step), pose, {}, full_);
    full_read_ = true;
    layers_[i].rates(full_, rates_[i]);
    return false;
}

}  // namespace bvc3d

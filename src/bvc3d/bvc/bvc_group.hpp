#pragma once
// BVC stage: the layers of several models that read one source of returns (an experiment's models sharing a walk).
// Takes: a source and the layers' parameters. Gives: each layer's rates for a step's pose, and which rows of the
// source's beam table the layers need. Each layer's rates are bit-identical to the layer alone.
//
// Per step the source is read once, casting only the rows some layer needs (at a level pose; a tilted pose casts
// every beam); layers whose parameters differ only in their elevations read their sums from one layer that sums the
// union of their elevations once (each keeps its own truncation bound); a layer whose bound fails (almost nothing
// in view) is computed again from a full read of the scan.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "bvc3d/bvc/boundary_vector_layer.hpp"
#include "bvc3d/core/geometry.hpp"
#include "bvc3d/sensor/return_source.hpp"

namespace bvc3d {

class BvcLayerGroup {
public:
    explicit BvcLayerGroup(std::shared_ptr<ReturnSource> source);

    const std::shared_ptr<ReturnSource>& source() const { return source_; }
    // A layer reading this group's source; returns its index. All layers are added before the first step.
    std::size_t add(const BvcParams& params);
    std::size_t size() const { return layers_.size(); }
    const BoundaryVectorLayer& layer(std::size_t i) const { return layers_[i]; }
    // The rows of the source's beam table some layer needs (empty without a beam table).
    const std::vector<char>& rows() const { return rows_; }

    // Layer i's rates at model step `step` (its pose): the first call of a step reads the source and computes every
    // layer's rates; the others read them. Steps come in order.
    void rates(std::int64_t step, const Pose& pose, std::size_t i, std::span<double> out);
    // Steps at which layer i's bound failed and the scan was read again in full.
    std::int64_t full_scan_fallbacks(std::size_t i) const { return fallbacks_[i]; }

private:
    void plan();  // the plans, the rows and the shared sums, once every layer is known
    void step(std::int64_t step, const Pose& pose);
    bool layer_rates(std::size_t i, std::int64_t step, const Pose& pose);

    std::shared_ptr<ReturnSource> source_;
    std::vector<BoundaryVectorLayer> layers_;
    std::vector<ScanPlan> plans_;  // per layer; empty rows without a beam table
    std::vector<char> rows_;
    // Layers that read their sums from one union layer: shared_[u], and per layer shared_of_ (-1: sums its own).
    struct SharedSums {
        std::vector<std::size_t> layers;
        std::unique_ptr<BoundaryVectorLayer> layer;
        ScanPlan plan;
    };
    std::vector<SharedSums> shared_;
    std::vector<int> shared_of_;
    bool planned_ = false;
    std::vector<std::vector<double>> rates_;  // per layer, this step's
    Scan scan_, full_;
    bool full_read_ = false;
    std::int64_t step_ = -1;
    std::vector<std::int64_t> fallbacks_;  // per layer
};

}  // namespace bvc3d

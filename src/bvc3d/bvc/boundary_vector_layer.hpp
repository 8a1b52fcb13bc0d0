#pragma once
// BVC stage (docs/model-reference.md#boundary-vector-cells): a layer of boundary vector cells tuned to distance,
// allocentric azimuth and elevation; the equation and its tuning curves are in tuning.hpp.
// Takes: LiDAR returns (range, azimuth, elevation), from a beam table or any point set. Gives: one rate per cell,
// cell i = (l, k, m) at index (l·n_dir + k)·n_per_axis + m, for preferred elevation psi_l, azimuth
// theta_k = 2πk/n_dir and distance d_m = m·max_dist/(n_per_axis - 1).
//
// raw_exact is the definition; raw and rates compute it fast (pruned_sums.hpp: terms that are all but zero left
// out, within 1e-7 of the largest sum by the bound of truncation_bound.hpp, else the full sum). A layer keeps the
// fast path's buffers: it is not shared between threads.
#include <memory>
#include <span>
#include <vector>

#include "bvc3d/bvc/bvc_params.hpp"
#include "bvc3d/bvc/nearest_beam.hpp"
#include "bvc3d/bvc/scan_plan.hpp"
#include "bvc3d/bvc/truncation_bound.hpp"
#include "bvc3d/bvc/tuning.hpp"
#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d {

class PrunedSums;  // pruned_sums.hpp, private to the library

class BoundaryVectorLayer {
public:
    explicit BoundaryVectorLayer(BvcParams params);
    // A copy has the same parameters and workspaces of its own (their contents carry nothing between calls).
    BoundaryVectorLayer(const BoundaryVectorLayer& other);
    BoundaryVectorLayer& operator=(const BoundaryVectorLayer& other);
    BoundaryVectorLayer(BoundaryVectorLayer&&) noexcept;
    BoundaryVectorLayer& operator=(BoundaryVectorLayer&&) noexcept;
    ~BoundaryVectorLayer();

    const BvcParams& params() const { return p_; }
    std::size_t n_cells() const { return static_cast<std::size_t>(p_.n_cells()); }

    // Input hygiene: a return whose range is NaN or +inf means "no return" and is skipped; a negative range, -inf,
    // or a non-finite angle throws InputError naming the return.
    //
    // The definition: the full sum of tuning.hpp over every return, no pruning (for checking, and the fallback).
    void raw_exact(std::span<const LidarReturn> returns, std::span<double> out) const;
    // The same sums to within 1e-7 of the largest (any point set).
    void raw(std::span<const LidarReturn> returns, std::span<double> out) const;
    // Normalized rates (per_step_max: raw / (2·max raw), so the largest is exactly 0.5).
    void rates(std::span<const LidarReturn> returns, std::span<double> out) const;

    // Which rows of a scanner's beam table this layer needs (scan_plan.hpp).
    using ScanPlan = bvc3d::ScanPlan;
    ScanPlan plan(const LidarSpec& sensor) const { return plan_scan(p_, sensor); }
    // Rates from a scan of the plan's sensor at a level pose, cast with plan.rows (returns of other rows, e.g. cast
    // for another model, are ignored). Returns false, leaving `out` unspecified, if the truncation bound is not met:
    // the caller then casts every row and calls rates().
    bool rates_pruned(std::span<const LidarReturn> returns, const ScanPlan& plan, std::span<double> out) const;

    // Several models on one scan (bvc_group.hpp): the sums of one (return, layer) pair do not depend on the other
    // layers, so a layer whose parameters equal this one's but for its elevations can read the sums of those it has
    // from a layer that summed their union once. sum_pruned sums (the union's side); rates_pruned_shared gives what
    // rates_pruned gives, the same bits and the same verdict of the truncation bound (which depends on the scan's
    // rows, not on the sums), reading the sums from `summed` (which must hold every elevation of this layer and have
    // summed the same scan).
    bool can_share_sums(const BvcParams& other) const;
    void sum_pruned(std::span<const LidarReturn> returns, const ScanPlan& plan) const;
    bool rates_pruned_shared(std::span<const LidarReturn> returns, const ScanPlan& plan,
                             const BoundaryVectorLayer& summed, std::span<double> out) const;

private:
    // The rates from `summed`'s sums of a planned pass (this layer's own, or a union's), if this layer's bound for
    // that pass's runs is met.
    bool planned_rates(const ScanPlan& plan, const BoundaryVectorLayer& summed, std::span<double> out) const;
    void normalize(std::span<double> out, double largest) const;  // largest: the largest of out
    void check_size(std::span<double> out) const;

    BvcParams p_;
    LayerTuning tuning_;
    pruning::Windows windows_;
    // The fast paths' workspaces (buffers that a step reuses; their contents carry nothing between calls).
    std::unique_ptr<PrunedSums> sums_;  // never null but after a move
    mutable NearestBeamReading nearest_;
};

}  // namespace bvc3d

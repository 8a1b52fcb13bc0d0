#include "bvc3d/bvc/boundary_vector_layer.hpp"

#include <algorithm>

#include "bvc3d/bvc/bvc_kernels.hpp"
#include "bvc3d/bvc/pruned_sums.hpp"
#include "bvc3d/bvc/return_check.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d {

namespace {
const BvcParams& validated(const BvcParams& p) {
    p.validate();
    return p;
}
}  // namespace

BoundaryVectorLayer::BoundaryVectorLayer(BvcParams params)
    : p_(std::move(params)),
      tuning_(validated(p_)),
      windows_(tuning_),
      sums_(std::make_unique<PrunedSums>(tuning_)),
      nearest_(tuning_) {}

BoundaryVectorLayer::BoundaryVectorLayer(const BoundaryVectorLayer& other)
    : p_(other.p_),
      tuning_(other.tuning_),
      windows_(other.windows_),
      sums_(std::make_unique<PrunedSums>(tuning_)),
      nearest_(tuning_) {}

BoundaryVectorLayer& BoundaryVectorLayer::operator=(const BoundaryVectorLayer& other) {
    if (this != &other) *this = BoundaryVectorLayer(other);
    return *this;
}

BoundaryVectorLayer::BoundaryVectorLayer(BoundaryVectorLayer&&) noexcept = default;
BoundaryVectorLayer& BoundaryVectorLayer::operator=(BoundaryVectorLayer&&) noexcept = default;
BoundaryVectorLayer::~BoundaryVectorLayer() = default;

void BoundaryVectorLayer::check_size(std::span<double> out) const {
    if (out.size() != n_cells()) throw InputError("BVC layer: output has the wrong size");
}

void BoundaryVectorLayer::raw_exact(std::span<const LidarReturn> returns, std::span<double> out) const {
    check_size(out);
    std::fill(out.begin(), out.end(), 0.0);
    if (p_.reading == BvcReading::nearest_beam) {
        nearest_.raw(returns, out, false);
        return;
    }
    const LayerTuning& t = tuning_;
    const int L = t.n_layers(), K = t.n_dir, M = t.n_per_axis;
    std::vector<double> E(L), A(K), D(M);
    for (std::size_t j = 0; j < returns.size(); ++j) {
        const LidarReturn& ret = returns[j];
        if (is_no_return(ret)) continue;
        check_return(ret, j);
        for (int l = 0; l < L; ++l) E[l] = t.planar() ? 1.0 : t.elevation(ret.elevation - t.elevations[l]);
        for (int k = 0; k < K; ++k) A[k] = t.azimuth(wrap_pi(ret.azimuth - k * two_pi / K));
        for (int m = 0; m < M; ++m) D[m] = t.distance(ret.range - m * t.spacing);
        for (int l = 0; l < L; ++l)
            for (int k = 0; k < K; ++k)
                for (int m = 0; m < M; ++m) out[(static_cast<std::size_t>(l) * K + k) * M + m] += E[l] * A[k] * D[m];
    }
}

void BoundaryVectorLayer::raw(std::span<const LidarReturn> returns, std::span<double> out) const {
    check_size(out);
    if (p_.reading == BvcReading::nearest_beam) {
        std::fill(out.begin(), out.end(), 0.0);
        if (!nearest_.raw(returns, out, true)) nearest_.raw(returns, out, false);
        return;
    }
    const std::size_t valid = sums_->sum_unplanned(returns);
    sums_->copy_sums(p_, true, out);
    const double max_raw = kernels::largest(out.data(), out.size());
    if (!(pruning::unplanned_bound(tuning_, sums_->weights(), valid) <= pruning::tolerance * max_raw))
        raw_exact(returns, out);
}

void BoundaryVectorLayer::normalize(std::span<double> out, double mx) const {
    if (p_.normalization == BvcNormalization::per_step_max) {
        if (mx > 0) {
            kernels::divide(out.data(), out.size(), 2.0 * mx);  // exact 0.5 at the maximum
        } else {
            std::fill(out.begin(), out.end(), 0.0);
        }
    } else if (p_.normalization == BvcNormalization::fixed) {
        kernels::divide(out.data(), out.size(), p_.norm_constant);
    }
}

void BoundaryVectorLayer::rates(std::span<const LidarReturn> returns, std::span<double> out) const {
    raw(returns, out);
    normalize(out, kernels::largest(out.data(), out.size()));
}

bool BoundaryVectorLayer::rates_pruned(std::span<const LidarReturn> returns, const ScanPlan& plan,
                                       std::span<double> out) const {
    check_size(out);
    if (p_.reading == BvcReading::nearest_beam) {
        rates(returns, out);
        return true;
    }
    sums_->sum_planned(returns, plan);
    return planned_rates(plan, *this, out);
}

bool BoundaryVectorLayer::can_share_sums(const BvcParams& o) const {
    // Everything but the elevations, which only select layers (and planar models share only with planar ones).
    return p_.reading == BvcReading::gaussian && o.reading == BvcReading::gaussian &&
           p_.elevations.empty() == o.elevations.empty() && p_.n_dir == o.n_dir && p_.n_per_axis == o.n_per_axis &&
           p_.max_dist == o.max_dist && p_.sigma_r == o.sigma_r && p_.sigma_theta == o.sigma_theta &&
           p_.sigma_phi == o.sigma_phi;
}

void BoundaryVectorLayer::sum_pruned(std::span<const LidarReturn> returns, const ScanPlan& plan) const {
    sums_->sum_planned(returns, plan);  // the bound is each reader's own (planned_rates)
}

bool BoundaryVectorLayer::rates_pruned_shared(std::span<const LidarReturn>, const ScanPlan& plan,
                                              const BoundaryVectorLayer& summed, std::span<double> out) const {
    check_size(out);
    if (!can_share_sums(summed.p_))
        throw InputError("BVC layer: cannot read the sums of a layer with other parameters");
    return planned_rates(plan, summed, out);
}

bool BoundaryVectorLayer::planned_rates(const ScanPlan& plan, const BoundaryVectorLayer& summed,
                                        std::span<double> out) const {
    summed.sums_->copy_sums(p_, &summed == this, out);
    const double max_raw = kernels::largest(out.data(), out.size());
    if (!(pruning::planned_bound(tuning_, windows_, plan, summed.sums_->runs()) <= pruning::tolerance * max_raw))
        return false;
    normalize(out, max_raw);
    return true;
}

}  // namespace bvc3d

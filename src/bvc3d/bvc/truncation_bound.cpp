#include "bvc3d/bvc/truncation_bound.hpp"

#include <algorithm>

#include "bvc3d/bvc/scan_plan.hpp"

namespace bvc3d::pruning {

namespace {

// Cases a, c, b and e of the derivation for one (layer, direction), from the sums of their weights.
double term_bound(const LayerTuning& t, double kept, double dropped, double evaluated, double far) {
    const double c_r = t.distance.peak, c_theta = t.azimuth.peak;
    return kept * c_r * tiny_r + dropped * c_r + evaluated * c_theta * c_r * tiny_theta + far * c_theta * c_r * tiny_r;
}

// Case d: the elevation factors below tiny_phi of `returns` returns.
double elevation_tail(const LayerTuning& t, std::size_t returns) {
    return t.planar() ? 0.0
                      : static_cast<double>(returns) * t.elevation.peak * t.azimuth.peak * t.distance.peak * tiny_phi;
}

}  // namespace

void PrunedWeights::reset(int layers, int directions) {
    const auto lk = static_cast<std::size_t>(layers) * static_cast<std::size_t>(directions);
    kept.assign(lk, 0.0);
    dropped.assign(lk, 0.0);
    evaluated.assign(static_cast<std::size_t>(layers), 0.0);
    far.assign(static_cast<std::size_t>(layers), 0.0);
}

double unplanned_bound(const LayerTuning& t, const PrunedWeights& w, std::size_t valid) {
    const int L = t.n_layers(), K = t.n_dir;
    double bound = 0;
    for (int l = 0; l < L; ++l)
        for (int k = 0; k < K; ++k) {
            const std::size_t lk = static_cast<std::size_t>(l) * K + k;
            bound = std::max(bound, term_bound(t, w.kept[lk], w.dropped[lk], w.evaluated[l], w.far[l]));
        }
    return bound + elevation_tail(t, valid);
}

double planned_bound(const LayerTuning& t, const Windows& win, const ScanPlan& plan, std::span<const Run> runs) {
    // The terms of unplanned_bound, with each run's Σ_returns A_k (any direction k) at most the lattice bound of the
    // rows its label can be (and at most A.peak per return), and a row the plan did not cast bounded by the plan. It
    // depends on the scan's rows and this layer's elevations only.
    const int L = t.n_layers();
    std::vector<double> kept(L, 0.0), dropped(L, 0.0), evaluated(L, 0.0), far(L, 0.0);
    std::size_t valid = 0;
    for (const Run& run : runs) {
        if (plan.skips(run.elevation)) continue;
        valid += run.valid;
        const double n = static_cast<double>(run.valid);
        const double angles = std::min(plan.angular_sum * plan.rows_per_label, n * t.azimuth.peak);
        for (int l = 0; l < L; ++l) {
            const ElevationSplit e = split_elevation(t, win, l, run.elevation);
            kept[l] += e.kept * angles;
            dropped[l] += e.dropped * angles;
            evaluated[l] += (e.kept + e.dropped) * n;
            far[l] += e.kept * static_cast<double>(run.far);
        }
    }
    double bound = 0;
    for (int l = 0; l < L; ++l)
        bound = std::max(bound, term_bound(t, kept[l], dropped[l], evaluated[l], far[l]) + plan.skipped_bound[l]);
    return bound + elevation_tail(t, std::max(valid, plan.beams));
}

}  // namespace bvc3d::pruning

#pragma once
// BVC stage: the model's equation (docs/model-reference.md#boundary-vector-cells, the paper's eq. 1-2) and its
// three tuning curves, written once. Takes: a layer's parameters. Gives: the preferred distance, azimuth and
// elevation of each cell and the factor each curve gives a return. The definition (BoundaryVectorLayer::raw_exact),
// the row planner (scan_plan.hpp), the truncation bound (truncation_bound.hpp) and the fast path (pruned_sums.hpp)
// all read the curves from here.
//
//   raw_i = Σ_j  D(r_j − d_m) · A(wrap(θ_j − θ_k)) · E(φ_j − ψ_l)        cell i = (l, k, m), i = (l·K + k)·M + m
//
// over the returns j = (range r, allocentric azimuth θ, elevation φ), with d_m = m·max_dist/(M − 1),
// θ_k = 2πk/K, ψ_l the layers' elevations, wrap() into (−π, π], and each curve a normalised Gaussian
// G(x; σ) = exp(−x²/2σ²)/√(2πσ²) of its own width. The 2-D model (no elevations) has E = 1.
//
// What the fast path relies on, so a new curve must keep or replace it: a curve is even, peaks at 0 and falls
// monotonically with |x| (its window, where it is at least `tiny` of its peak, is one interval); the azimuth curve
// integrates to 1 over the line (the planner's lattice bound); the distance curve is a Gaussian, whose profile over
// the evenly spaced d_m the kernel evaluates as a recurrence (pruned_sums.hpp). Swapping the elevation curve for a
// von Mises one touches ElevationTuning and the truncation bound's derivation only.
#include <cmath>
#include <numbers>
#include <vector>

#include "bvc3d/bvc/bvc_params.hpp"

namespace bvc3d {

// peak · exp(−x²·h), h = 1/2σ², peak = 1/√(2πσ²): G(x; σ).
struct GaussianCurve {
    double sigma = 1.0;
    double peak = 0.0;  // the value at x = 0
    double h = 0.0;     // 1/2σ²

    explicit GaussianCurve(double width)
        : sigma(width), peak(1.0 / std::sqrt(2.0 * std::numbers::pi * width * width)), h(0.5 / (width * width)) {}
    double operator()(double x) const { return peak * std::exp(-x * x * h); }
    // |x| beyond which the curve is below `tiny` of its peak.
    double window(double tiny) const { return sigma * std::sqrt(2.0 * std::log(1.0 / tiny)); }
};

// The three curves of one layer.
struct DistanceTuning : GaussianCurve {  // D(r − d_m; σ_r)
    using GaussianCurve::GaussianCurve;
};
struct AzimuthTuning : GaussianCurve {  // A(wrap(θ − θ_k); σ_θ)
    using GaussianCurve::GaussianCurve;
};
struct ElevationTuning : GaussianCurve {  // E(φ − ψ_l; σ_φ)
    using GaussianCurve::GaussianCurve;
};

// A layer's curves and preferred values.
struct LayerTuning {
    DistanceTuning distance;
    AzimuthTuning azimuth;
    ElevationTuning elevation;
    std::vector<double> elevations;  // ψ_l; empty: the 2-D model, E = 1
    int n_dir, n_per_axis;
    double spacing;  // d_m = m·spacing

    explicit LayerTuning(const BvcParams& p)
        : distance(p.sigma_r),
          azimuth(p.sigma_theta),
          elevation(p.sigma_phi),
          elevations(p.elevations),
          n_dir(p.n_dir),
          n_per_axis(p.n_per_axis),
          spacing(p.spacing()) {}
    int n_layers() const { return elevations.empty() ? 1 : static_cast<int>(elevations.size()); }
    bool planar() const { return elevations.empty(); }
};

}  // namespace bvc3d

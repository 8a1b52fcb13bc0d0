#pragma once
// BVC stage: the fast path's guarantee. Takes: a layer's tuning and what a pass of the fast path pruned. Gives:
// which factors the fast path treats as zero, and a bound on what that drops from any cell. A pass's sums are used
// only when the bound is below `tolerance` of the step's largest sum (the model asks for 1e-6 of the largest rate,
// docs/model-reference.md#exactness); otherwise the layer computes the full sum.
//
// Derivation. A factor below `tiny` of its curve's peak is outside the curve's window (tuning.hpp: the curves fall
// monotonically from 0). Every term E·A·D of cell (l, k, m) that a pass drops is one of:
//   (a) D outside its window, for a summed (return, layer, direction):     ≤ E·A · D.peak·tiny_r
//   (b) A outside its window, for a (return, layer) whose E was evaluated:  ≤ E · A.peak·tiny_theta · D.peak
//   (c) E within [tiny_phi, tiny_row) of its peak: not summed, E·A known:   ≤ E·A · D.peak
//   (d) E below tiny_phi of its peak: not even evaluated:                   ≤ E.peak·tiny_phi · A.peak · D.peak
//   (e) a return whose distance window holds no cell at all:                ≤ E · A.peak · D.peak·tiny_r
// Summed over the returns, per (l, k): term_bound(Σ(a), Σ(c), Σ(b), Σ(e)) + elevation_tail(returns). A planned pass
// (a beam table, scan_plan.hpp) does not record A return by return: it bounds each row's Σ A by the lattice bound
// of its evenly spaced columns, and the rows it did not cast by the plan's own bound.
#include <cmath>
#include <cstddef>
#include <span>
#include <vector>

#include "bvc3d/bvc/tuning.hpp"

namespace bvc3d {

struct ScanPlan;

namespace pruning {

// Factors below these fractions of their peak are treated as zero. Elevation has two tiers: a (return, layer) below
// tiny_row is not summed but its exact weight enters the bound (c); below tiny_phi it is not even evaluated (d).
inline constexpr double tiny_r = 1e-9;
inline constexpr double tiny_theta = 1e-10;
inline constexpr double tiny_row = 1e-8;
inline constexpr double tiny_phi = 1e-13;
inline constexpr double tolerance = 1e-7;  // of the step's largest sum

// |x| within which each curve is at least its tiny fraction of its peak.
struct Windows {
    double r, theta, phi, row;
    explicit Windows(const LayerTuning& t)
        : r(t.distance.window(tiny_r)),
          theta(t.azimuth.window(tiny_theta)),
          phi(t.elevation.window(tiny_phi)),
          row(t.elevation.window(tiny_row)) {}
};

// Layer l's elevation factor for a return at φ as a pass treats it: summed (`kept`), bounded by its exact value
// (`dropped`, case c), or neither (case d). The 2-D model's factor is 1.
struct ElevationSplit {
    double kept = 0, dropped = 0;
};
inline ElevationSplit split_elevation(const LayerTuning& t, const Windows& w, int l, double phi) {
    if (t.planar()) return {1.0, 0.0};
    const double x = phi - t.elevations[static_cast<std::size_t>(l)];
    if (std::abs(x) <= w.row) return {t.elevation(x), 0.0};
    if (std::abs(x) <= w.phi) return {0.0, t.elevation(x)};
    return {};
}

// What an unplanned pass dropped, return by return: per (layer, direction) Σ E·A of summed (a) and of case-c
// elevations; per layer Σ E over the returns whose E was evaluated (b) and Σ E over those with no cell in reach (e).
struct PrunedWeights {
    std::vector<double> kept, dropped;   // L × K
    std::vector<double> evaluated, far;  // L
    void reset(int layers, int directions);
};

// A planned pass's bookkeeping: per run of returns of one scanner row, its elevation, the returns it counted and
// those with no cell in reach.
struct Run {
    double elevation;
    std::size_t valid, far;
};

// The bound on any cell's dropped terms after an unplanned pass over `valid` returns.
double unplanned_bound(const LayerTuning& t, const PrunedWeights& w, std::size_t valid);
// The same after a planned pass of `plan`'s scan with these runs (the reader's own tuning: a layer reading another's
// shared sums gets the verdict of its own pass).
double planned_bound(const LayerTuning& t, const Windows& w, const ScanPlan& plan, std::span<const Run> runs);

}  // namespace pruning
}  // namespace bvc3d

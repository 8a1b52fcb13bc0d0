#include "bvc3d/bvc/scan_plan.hpp"

#include <cmath>

#include "bvc3d/bvc/truncation_bound.hpp"
#include "bvc3d/bvc/tuning.hpp"
#include "bvc3d/core/angles.hpp"

namespace bvc3d {

ScanPlan plan_scan(const BvcParams& params, const LidarSpec& sensor) {
    const LayerTuning t(params);
    ScanPlan plan;
    const int L = t.n_layers();
    const std::vector<double>& rows = sensor.row_labels();  // the elevations the returns carry
    plan.rows.assign(rows.size(), 1);
    plan.skipped_bound.assign(L, 0.0);
    plan.beams = sensor.beam_count();
    plan.columns = static_cast<std::size_t>(sensor.azimuth_count);
    // A row's beams are evenly spaced in azimuth (δ apart), so for any heading and direction Σ_columns A(x) <=
    // A.peak + 1/δ (a unimodal function that integrates to 1, summed over a lattice). linspace labels are
    // δ' = 2π/(n−1) > δ apart with one azimuth twice (0 and 2π): one term more.
    const double delta = two_pi / sensor.azimuth_count;
    const double repeated = sensor.azimuth_labels == AzimuthLabels::linspace ? 1.0 : 0.0;
    plan.angular_sum = t.azimuth.peak * (1.0 + std::sqrt(two_pi) * t.azimuth.sigma / delta + repeated);
    std::vector<double> labels = rows;
    std::sort(labels.begin(), labels.end());
    for (auto at = labels.begin(); at != labels.end();) {
        const auto next = std::upper_bound(at, labels.end(), *at);
        plan.rows_per_label = std::max(plan.rows_per_label, static_cast<int>(next - at));
        at = next;
    }
    if (t.planar() || params.reading == BvcReading::nearest_beam) return plan;  // reads every row
    const double row_window = t.elevation.window(pruning::tiny_row);
    for (std::size_t i = 0; i < rows.size(); ++i) {
        bool needed = false;
        for (double psi : t.elevations) needed = needed || std::abs(rows[i] - psi) <= row_window;
        if (needed) continue;
        plan.rows[i] = 0;
        plan.skipped_rows.push_back(rows[i]);
        for (int l = 0; l < L; ++l)
            plan.skipped_bound[l] += t.elevation(rows[i] - t.elevations[l]) * plan.angular_sum * t.distance.peak;
    }
    return plan;
}

}  // namespace bvc3d

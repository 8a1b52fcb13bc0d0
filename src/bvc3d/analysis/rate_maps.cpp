#include "bvc3d/analysis/rate_maps.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d::analysis {

namespace {

void check_quantile(double q) {
    if (!(q >= 0.0 && q <= 1.0)) throw InputError("quantile must lie in [0, 1], got " + std::to_string(q));
}

}  // namespace

double percentile_linear(std::span<double> v, double percent) {
    if (v.empty()) throw InputError("percentile of an empty array");
    const auto n = static_cast<std::ptrdiff_t>(v.size());
    const double q = percent / 100;  // np.true_divide(q, 100)
    const double virtual_index = static_cast<double>(n - 1) * q;
    std::ptrdiff_t prev = static_cast<std::ptrdiff_t>(std::floor(virtual_index)), next = prev + 1;
    double prev_for_gamma = static_cast<double>(prev);
    if (virtual_index >= static_cast<double>(n - 1)) {  // numpy takes index -1 for both
        prev = next = n - 1;
        prev_for_gamma = -1.0;
    } else if (virtual_index < 0) {
        prev = next = 0;
        prev_for_gamma = 0.0;
    }
    const double gamma = virtual_index - prev_for_gamma;
    std::nth_element(v.begin(), v.begin() + prev, v.end());
    const double a = v[static_cast<std::size_t>(prev)];
    const double b = next == prev ? a : *std::min_element(v.begin() + next, v.end());
    // numpy's _lerp: a + d·t, or b − d·(1 − t) where t >= 0.5.
    const double d = b - a;
    return gamma >= 0.5 ? b - d * (1 - gamma) : a + d * gamma;
}

void threshold_and_normalize(RowMatrixXd& maps, double quantile) {
    check_quantile(quantile);
    if (maps.rows() == 0) return;
    const double percent = 100 * quantile;
    std::vector<double> scratch(static_cast<std::size_t>(maps.rows()));
    for (Eigen::Index c = 0; c < maps.cols(); ++c) {
        poll_cancel();
        auto col = maps.col(c);
        for (Eigen::Index b = 0; b < maps.rows(); ++b) scratch[static_cast<std::size_t>(b)] = col(b);
        const double threshold = percentile_linear(scratch, percent);
        double top = -INFINITY;
        for (Eigen::Index b = 0; b < maps.rows(); ++b) {
            if (col(b) < threshold) col(b) = 0.0;
            top = std::max(top, col(b));
        }
        if (top > 0) col /= top;
        else col.setZero();  // a silent cell: no field rather than 0/0
    }
}

void RateMapParams::validate() const {
    check_quantile(quantile);
    if (extent) extent->validate();
}

template <class T>
RateMaps rate_maps(std::shared_ptr<const Grid> grid, const Eigen::Ref<const Points>& positions,
                   const Eigen::Ref<const RowMatrixX<T>>& rates, double quantile) {
    check_quantile(quantile);
    RateMaps out;
    out.bins = bin_positions(*grid, positions);
    out.grid = std::move(grid);
    out.mean = bin_means<T>(out.bins, rates);
    out.map = out.mean;
    threshold_and_normalize(out.map, quantile);
    return out;
}

template <class T>
RateMaps rate_maps(std::span<const double> x, std::span<const double> y, const Eigen::Ref<const RowMatrixX<T>>& rates,
                   const RateMapParams& params) {
    params.validate();
    return rate_maps<T>(std::make_shared<HexGrid>(HexGrid::fit(x, y, params.gridsize, params.extent)),
                        positions_2d(x, y), rates, params.quantile);
}

template RateMaps rate_maps<float>(std::shared_ptr<const Grid>, const Eigen::Ref<const Points>&,
                                   const Eigen::Ref<const RowMatrixXf>&, double);
template RateMaps rate_maps<double>(std::shared_ptr<const Grid>, const Eigen::Ref<const Points>&,
                                    const Eigen::Ref<const RowMatrixXd>&, double);
template RateMaps rate_maps<float>(std::span<const double>, std::span<const double>,
                                   const Eigen::Ref<const RowMatrixXf>&, const RateMapParams&);
template RateMaps rate_maps<double>(std::span<const double>, std::span<const double>,
                                    const Eigen::Ref<const RowMatrixXd>&, const RateMapParams&);

}  // namespace bvc3d::analysis

#pragma once
// Rate maps (docs/analysis.md): per cell, the mean rate in each visited bin, then values below the
// cell's q-quantile set to 0 and the map divided by its maximum.
// Takes: positions (N × D, or x and y) and rates (one row per sample, one column per cell).
// Gives: the bins, the raw mean rates and the thresholded, normalized maps (bins × cells).
#include <memory>
#include <optional>
#include <span>

#include "bvc3d/analysis/hexbin.hpp"

namespace bvc3d::analysis {

// numpy.percentile(values, percent) with numpy 1.24's default 'linear' method, bit for bit
// (same virtual index, same two-sided lerp). Reorders `values`; `values` must not be empty.
double percentile_linear(std::span<double> values, double percent);

// Per column: entries below numpy.percentile(column, 100·quantile) become 0, then the column is
// divided by its maximum. A column whose maximum is <= 0 (a silent cell) becomes all zeros, so
// a map never holds NaN. quantile must lie in [0, 1].
void threshold_and_normalize(RowMatrixXd& maps, double quantile);

struct RateMapParams {
    int gridsize = 50;             // hexagons across x (matplotlib's gridsize)
    double quantile = 0.1;         // the paper's 10 % threshold
    std::optional<Extent> extent;  // default: the trajectory's own min/max
    void validate() const;
};

struct RateMaps {
    std::shared_ptr<const Grid> grid;
    Bins bins;
    RowMatrixXd mean;  // bins × cells: mean rate per bin (matplotlib's hexbin values in 2-D)
    RowMatrixXd map;   // bins × cells: thresholded and normalized to a maximum of 1
};

// On any grid; positions have grid->dims() columns.
template <class T>
RateMaps rate_maps(std::shared_ptr<const Grid> grid, const Eigen::Ref<const Points>& positions,
                   const Eigen::Ref<const RowMatrixX<T>>& rates, double quantile);
// 2-D: hexagonal bins exactly as matplotlib's hexbin.
template <class T>
RateMaps rate_maps(std::span<const double> x, std::span<const double> y, const Eigen::Ref<const RowMatrixX<T>>& rates,
                   const RateMapParams& params = {});

}  // namespace bvc3d::analysis

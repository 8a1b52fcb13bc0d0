#include "bvc3d/analysis/cell_stats.hpp"

#include <cmath>
#include <limits>

namespace bvc3d::analysis {

CellStats cell_stats(const RateMaps& maps) {
    const Eigen::Index n_bins = maps.mean.rows(), n_cells = maps.mean.cols();
    const auto cells = static_cast<std::size_t>(n_cells);
    CellStats s;
    s.peak_rate.assign(cells, std::numeric_limits<double>::quiet_NaN());
    s.mean_rate.assign(cells, std::numeric_limits<double>::quiet_NaN());
    s.field_area.assign(cells, 0.0);
    s.spatial_info.assign(cells, std::numeric_limits<double>::quiet_NaN());
    s.spatial_info_per_rate.assign(cells, std::numeric_limits<double>::quiet_NaN());
    if (n_bins == 0) return s;

    double binned = 0;
    for (const auto c : maps.bins.counts) binned += static_cast<double>(c);
    Eigen::VectorXd occupancy(n_bins);
    for (Eigen::Index b = 0; b < n_bins; ++b)
        occupancy(b) = static_cast<double>(maps.bins.counts[static_cast<std::size_t>(b)]) / binned;
    const double area = maps.grid->bin_measure();
    for (Eigen::Index c = 0; c < n_cells; ++c) {
        const auto k = static_cast<std::size_t>(c);
        const auto rate = maps.mean.col(c);
        s.peak_rate[k] = rate.maxCoeff();
        const double mean = occupancy.dot(rate);
        s.mean_rate[k] = mean;
        s.field_area[k] = static_cast<double>((maps.map.col(c).array() > 0.5).count()) * area;
        double info = 0;
        if (mean > 0)
            for (Eigen::Index b = 0; b < n_bins; ++b)
                if (rate(b) > 0) info += occupancy(b) * rate(b) * std::log2(rate(b) / mean);
        s.spatial_info[k] = info;
        if (mean > 0) s.spatial_info_per_rate[k] = info / mean;
    }
    return s;
}

}  // namespace bvc3d::analysis

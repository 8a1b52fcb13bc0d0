#include "bvc3d/analysis/hexbin.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"

namespace bvc3d::analysis {

void Extent::validate() const {
    if (!std::isfinite(xmin) || !std::isfinite(xmax) || !std::isfinite(ymin) || !std::isfinite(ymax))
        throw InputError("extent: (xmin, xmax, ymin, ymax) must be finite");
    if (!(xmin < xmax) || !(ymin < ymax))
        throw InputError("extent: need xmin < xmax and ymin < ymax, got (" + std::to_string(xmin) + ", " +
                         std::to_string(xmax) + ", " + std::to_string(ymin) + ", " + std::to_string(ymax) + ")");
}

std::array<double, 2> nonsingular(double vmin, double vmax, double expander) {
    constexpr double tiny = 1e-15;
    if (!std::isfinite(vmin) || !std::isfinite(vmax)) return {-expander, expander};
    if (vmax < vmin) std::swap(vmin, vmax);
    const double maxabs = std::max(std::abs(vmin), std::abs(vmax));
    if (maxabs < (1e6 / tiny) * DBL_MIN) {  // DBL_MIN is numpy's finfo(float).tiny
        vmin = -expander;
        vmax = expander;
    } else if (vmax - vmin <= maxabs * tiny) {
        if (vmax == 0 && vmin == 0) {
            vmin = -expander;
            vmax = expander;
        } else {
            vmin -= expander * std::abs(vmin);
            vmax += expander * std::abs(vmax);
        }
    }
    return {vmin, vmax};
}

void check_positions(std::span<const double> x, std::span<const double> y) {
    if (x.size() != y.size())
        throw InputError("x and y must have the same length, got " + std::to_string(x.size()) + " and " +
                         std::to_string(y.size()));
    for (std::size_t i = 0; i < x.size(); ++i)
        if (!std::isfinite(x[i]) || !std::isfinite(y[i]))
            throw InputError("positions must be finite: sample " + std::to_string(i) + " is (" +
                             std::to_string(x[i]) + ", " + std::to_string(y[i]) + ")");
}

template <class T>
void check_values(const Eigen::Ref<const RowMatrixX<T>>& values, std::size_t n, const char* what) {
    if (static_cast<std::size_t>(values.rows()) != n)
        throw InputError(std::string(what) + " must have one row per sample: " + std::to_string(values.rows()) +
                         " rows for " + std::to_string(n) + " samples");
    for (Eigen::Index i = 0; i < values.rows(); ++i)
        for (Eigen::Index c = 0; c < values.cols(); ++c)
            if (!std::isfinite(values(i, c)))
                throw InputError(std::string(what) + " must be finite: row " + std::to_string(i) + ", column " +
                                 std::to_string(c) + " is " + std::to_string(values(i, c)));
}

HexGrid HexGrid::fit(std::span<const double> x, std::span<const double> y, int gridsize,
                     const std::optional<Extent>& extent) {
    if (gridsize < 2)
        throw InputError("gridsize must be >= 2 (matplotlib's grid has int(gridsize / sqrt(3)) rows), got " +
                         std::to_string(gridsize));
    check_positions(x, y);
    HexGrid g;
    g.nx = gridsize;
    g.ny = static_cast<int>(gridsize / std::sqrt(3.0));
    double xmin, xmax, ymin, ymax;
    if (extent) {
        extent->validate();
        xmin = extent->xmin, xmax = extent->xmax, ymin = extent->ymin, ymax = extent->ymax;
    } else {
        if (x.empty()) {
            xmin = ymin = 0.0;
            xmax = ymax = 1.0;
        } else {
            const auto [x0, x1] = std::minmax_element(x.begin(), x.end());
            const auto [y0, y1] = std::minmax_element(y.begin(), y.end());
            xmin = *x0, xmax = *x1, ymin = *y0, ymax = *y1;
        }
        // To avoid singular data (one point, a vertical line) matplotlib expands the ranges.
        const auto xr = nonsingular(xmin, xmax, 0.1), yr = nonsingular(ymin, ymax, 0.1);
        xmin = xr[0], xmax = xr[1], ymin = yr[0], ymax = yr[1];
    }
    // "the hexagons exactly cover the region from xmin to xmax. Need some padding to avoid
    // roundoff errors." (matplotlib pads x only.)
    const double padding = 1.e-9 * (xmax - xmin);
    xmin -= padding;
    xmax += padding;
    g.xmin = xmin;
    g.ymin = ymin;
    g.sx = (xmax - xmin) / g.nx;
    g.sy = (ymax - ymin) / g.ny;
    return g;
}

int HexGrid::bin_of(double x, double y) const {
    // Same operations in the same order as matplotlib (numpy.round is round-half-to-even = rint).
    const double ix = (x - xmin) / sx, iy = (y - ymin) / sy;
    const double ix1 = std::nearbyint(ix), iy1 = std::nearbyint(iy);
    const double ix2 = std::floor(ix), iy2 = std::floor(iy);
    const double a1 = ix - ix1, b1 = iy - iy1;
    const double a2 = ix - ix2 - 0.5, b2 = iy - iy2 - 0.5;
    const double d1 = a1 * a1 + 3.0 * (b1 * b1);
    const double d2 = a2 * a2 + 3.0 * (b2 * b2);
    if (d1 < d2) {  // lattice 1; out of range is dropped, not handed to lattice 2
        if (ix1 >= 0 && ix1 < nx + 1 && iy1 >= 0 && iy1 < ny + 1)
            return static_cast<int>(ix1) * (ny + 1) + static_cast<int>(iy1);
        return -1;
    }
    if (ix2 >= 0 && ix2 < nx && iy2 >= 0 && iy2 < ny)
        return lattice1_size() + static_cast<int>(ix2) * ny + static_cast<int>(iy2);
    return -1;
}

std::array<double, 2> HexGrid::center(int bin) const {
    const int n1 = lattice1_size();
    if (bin < n1) {
        const int i = bin / (ny + 1), j = bin % (ny + 1);
        return {static_cast<double>(i) * sx + xmin, static_cast<double>(j) * sy + ymin};
    }
    const int i = (bin - n1) / ny, j = (bin - n1) % ny;
    return {(static_cast<double>(i) + 0.5) * sx + xmin, (static_cast<double>(j) + 0.5) * sy + ymin};
}

HexBins bin_samples(const HexGrid& grid, std::span<const double> x, std::span<const double> y) {
    check_positions(x, y);
    HexBins out;
    out.grid = grid;
    const std::size_t n = x.size();
    std::vector<int> flat(n);
    std::vector<std::int64_t> count(static_cast<std::size_t>(grid.size()), 0);
    for (std::size_t i = 0; i < n; ++i) {
        flat[i] = grid.bin_of(x[i], y[i]);
        if (flat[i] >= 0) ++count[static_cast<std::size_t>(flat[i])];
    }
    // Only visited bins exist (matplotlib turns empty bins into NaN and removes them).
    std::vector<int> row_of(count.size(), -1);
    for (int b = 0; b < grid.size(); ++b)
        if (count[static_cast<std::size_t>(b)] > 0) {
            row_of[static_cast<std::size_t>(b)] = static_cast<int>(out.bins.size());
            out.bins.push_back(b);
            out.counts.push_back(count[static_cast<std::size_t>(b)]);
        }
    out.centers.resize(static_cast<Eigen::Index>(out.bins.size()), 2);
    for (std::size_t r = 0; r < out.bins.size(); ++r) {
        const auto c = grid.center(out.bins[r]);
        out.centers(static_cast<Eigen::Index>(r), 0) = c[0];
        out.centers(static_cast<Eigen::Index>(r), 1) = c[1];
    }
    out.sample_bin.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        out.sample_bin[i] = flat[i] < 0 ? -1 : row_of[static_cast<std::size_t>(flat[i])];
    return out;
}

HexBins hexbin(std::span<const double> x, std::span<const double> y, int gridsize, const std::optional<Extent>& extent) {
    return bin_samples(HexGrid::fit(x, y, gridsize, extent), x, y);
}

template <class T>
RowMatrixXd bin_means(const HexBins& bins, const Eigen::Ref<const RowMatrixX<T>>& values) {
    check_values<T>(values, bins.sample_bin.size(), "values");
    RowMatrixXd sum = RowMatrixXd::Zero(bins.size(), values.cols());
    for (std::size_t i = 0; i < bins.sample_bin.size(); ++i)
        if (const int b = bins.sample_bin[i]; b >= 0)
            sum.row(b) += values.row(static_cast<Eigen::Index>(i)).template cast<double>();
    for (int b = 0; b < bins.size(); ++b) sum.row(b) /= static_cast<double>(bins.counts[static_cast<std::size_t>(b)]);
    return sum;
}

template RowMatrixXd bin_means<float>(const HexBins&, const Eigen::Ref<const RowMatrixXf>&);
template RowMatrixXd bin_means<double>(const HexBins&, const Eigen::Ref<const RowMatrixXd>&);
template void check_values<float>(const Eigen::Ref<const RowMatrixXf>&, std::size_t, const char*);
template void check_values<double>(const Eigen::Ref<const RowMatrixXd>&, std::size_t, const char*);

}  // namespace bvc3d::analysis

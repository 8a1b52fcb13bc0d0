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

HexGrid HexGrid::fit(std::span<const double> x, std::span<const double> y, int gridsize,
                     const std::optional<Extent>& extent) {
    if (gridsize < 2)
        throw InputError("gridsize must be >= 2 (matplotlib's grid has int(gridsize / sqrt(3)) rows), got " +
                         std::to_string(gridsize));
    check_positions(positions_2d(x, y));
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
    HexBins out;
    static_cast<Bins&>(out) = bin_positions(grid, positions_2d(x, y));
    out.grid = grid;
    return out;
}

HexBins hexbin(std::span<const double> x, std::span<const double> y, int gridsize,
               const std::optional<Extent>& extent) {
    return bin_samples(HexGrid::fit(x, y, gridsize, extent), x, y);
}

}  // namespace bvc3d::analysis

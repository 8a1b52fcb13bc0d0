#pragma once
// Hexagonal binning exactly as matplotlib 3.6.3's Axes.hexbin(x, y, C, gridsize, extent,
// reduce_C_function=numpy.mean) does it (docs/analysis.md), for many value columns in one pass:
// the 2-D Grid.
// Takes: sample positions (x, y) and values (one row per sample). Gives: the visited bins in
// matplotlib's order, their centers, sample counts and per-column means.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "bvc3d/analysis/binning.hpp"

namespace bvc3d::analysis {

// matplotlib.transforms.nonsingular(vmin, vmax, expander, tiny=1e-15, increasing=True).
std::array<double, 2> nonsingular(double vmin, double vmax, double expander);

// Two interleaved rectangular lattices of hexagon centers. Lattice 1 has (nx+1)·(ny+1) centers at
// (i·sx + xmin, j·sy + ymin); lattice 2 has nx·ny centers offset by half a step in x and y.
// A flat bin index runs over lattice 1 (i·(ny+1) + j) and then lattice 2 (offset + i·ny + j):
// matplotlib's order of bins.
struct HexGrid : Grid {
    int nx = 0, ny = 0;         // nx = gridsize, ny = int(gridsize / sqrt(3))
    double xmin = 0, ymin = 0;  // lower-left lattice point (xmin includes matplotlib's padding)
    double sx = 0, sy = 0;      // lattice steps: hexagons are sx wide, rows sy apart

    // The grid matplotlib builds: extent = the data's min/max made nonsingular (expander 0.1)
    // unless given; then x (only x) is padded by 1e-9 of its range; sx = width/nx, sy = height/ny.
    // gridsize must be >= 2 (below that matplotlib's grid has no rows).
    static HexGrid fit(std::span<const double> x, std::span<const double> y, int gridsize,
                       const std::optional<Extent>& extent = {});

    int dims() const override { return 2; }
    int size() const override { return (nx + 1) * (ny + 1) + nx * ny; }
    int lattice1_size() const { return (nx + 1) * (ny + 1); }
    // Flat index of the bin holding (x, y), -1 if that bin lies outside the grid (matplotlib drops
    // such points). Nearest center in the metric dx² + 3·dy² of lattice units; a tie goes to lattice 2.
    int bin_of(double x, double y) const;
    int bin_of(const double* p) const override { return bin_of(p[0], p[1]); }
    std::array<double, 2> center(int bin) const;
    void center(int bin, double* out) const override {
        const auto c = center(bin);
        out[0] = c[0];
        out[1] = c[1];
    }
    // Area of one hexagon, m² when x, y are in meters: the two lattices tile each sx × sy cell twice.
    double bin_area() const { return 0.5 * sx * sy; }
    double bin_measure() const override { return bin_area(); }
};

// Samples in the visited bins of a hexagonal grid.
struct HexBins : Bins {
    HexGrid grid;
};

// Coordinates must have equal lengths and be finite (InputError otherwise).
HexBins bin_samples(const HexGrid& grid, std::span<const double> x, std::span<const double> y);
HexBins hexbin(std::span<const double> x, std::span<const double> y, int gridsize = 50,
               const std::optional<Extent>& extent = {});

}  // namespace bvc3d::analysis

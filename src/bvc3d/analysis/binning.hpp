#pragma once
// Bins: where samples fall. A Grid assigns a position (a row of D coordinates) to one of its bins:
// hexagons in 2-D (hexbin.hpp, exactly matplotlib's), voxels in 3-D (flying agents). Rate maps,
// decoding and cell statistics work on any Grid.
// Takes: positions (N × D). Gives: the visited bins in the grid's order, their centers, sample
// counts, each sample's bin, and per-column means over a bin's samples.
#include <cstdint>
#include <span>
#include <vector>

#include "bvc3d/analysis/types.hpp"

namespace bvc3d::analysis {

class Grid {
public:
    virtual ~Grid() = default;
    virtual int dims() const = 0;
    virtual int size() const = 0;  // bins in the grid, visited or not
    // Index of the bin holding `position` (dims() coordinates), -1 if that bin lies outside the grid.
    virtual int bin_of(const double* position) const = 0;
    virtual void center(int bin, double* out) const = 0;
    virtual double bin_measure() const = 0;  // area (m²) or volume (m³) of one bin
};

// Samples assigned to the visited bins of a grid.
struct Bins {
    std::vector<int> ids;              // grid index of each visited bin, ascending
    Points centers;                    // center of each visited bin (rows of D coordinates)
    std::vector<std::int64_t> counts;  // samples in each visited bin
    std::vector<int> sample_bin;       // per sample: row in `ids`, or -1 outside the grid
    int size() const { return static_cast<int>(ids.size()); }
};

// Positions must be finite with grid.dims() columns (InputError otherwise).
Bins bin_positions(const Grid& grid, const Eigen::Ref<const Points>& positions);

// Per visited bin, the mean of each column of `values` (one row per sample, finite) over the
// bin's samples: numpy.mean for every column at once, summed in double.
template <class T>
RowMatrixXd bin_means(const Bins& bins, const Eigen::Ref<const RowMatrixX<T>>& values);

// Throws InputError unless every position is finite (and has `dims` columns when dims > 0).
void check_positions(const Eigen::Ref<const Points>& positions, int dims = 0);
// Throws InputError unless `values` has `n` rows and only finite entries.
template <class T>
void check_values(const Eigen::Ref<const RowMatrixX<T>>& values, std::size_t n, const char* what);

// (x, y) spans as an N × 2 array of positions (InputError if their lengths differ).
Points positions_2d(std::span<const double> x, std::span<const double> y);

}  // namespace bvc3d::analysis

#pragma once
// Array types shared by the analysis stage. Samples are rows: a trial's rates are n_samples × n_cells,
// a rate map is n_bins × n_cells (row b = the population vector of bin b), as numpy lays them out.
// Positions and bin centers are rows of D coordinates (D = 2 for ground agents, 3 for flying ones).
#include <Eigen/Core>

namespace bvc3d::analysis {

template <class T>
using RowMatrixX = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatrixXd = RowMatrixX<double>;
using RowMatrixXf = RowMatrixX<float>;

// Positions or bin centers: one row of D coordinates (x, y[, z]) per sample or bin.
using Points = RowMatrixXd;
using Centers = Points;

// The rectangle a hexagonal grid covers (matplotlib's `extent`).
struct Extent {
    double xmin = 0.0, xmax = 1.0, ymin = 0.0, ymax = 1.0;
    void validate() const;  // finite, xmin < xmax, ymin < ymax; throws InputError
};

}  // namespace bvc3d::analysis

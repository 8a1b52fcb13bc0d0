#pragma once
// Array types shared by the analysis stage. Samples are rows: a trial's rates are n_samples × n_cells,
// a rate map is n_bins × n_cells (row b = the population vector of bin b), as numpy lays them out.
#include <Eigen/Core>

namespace bvc3d::analysis {

template <class T>
using RowMatrixX = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using RowMatrixXd = RowMatrixX<double>;
using RowMatrixXf = RowMatrixX<float>;

// Bin centres, one (x, y) row per bin.
using Centers = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

// The rectangle a hexagonal grid covers (matplotlib's `extent`).
struct Extent {
    double xmin = 0.0, xmax = 1.0, ymin = 0.0, ymax = 1.0;
    void validate() const;  // finite, xmin < xmax, ymin < ymax; throws InputError
};

}  // namespace bvc3d::analysis

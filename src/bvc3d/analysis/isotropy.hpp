#pragma once
// Field isotropy (docs/flying.md#analysis): how round a unimodal cell's 3-D place field is.
// Takes: bin centers (N × 3), rate maps (bins × cells), each cell's modality index and the DBSCAN
// parameters it was found with. Gives: per cell, the rate-weighted standard deviation of its field
// along z divided by the mean of its standard deviations along x and y.
#include <vector>

#include "bvc3d/analysis/modality.hpp"

namespace bvc3d::analysis {

// The field of a cell with MI = 1 is its one DBSCAN cluster among the bins where its map is > 0
// (noise bins left out); each bin weighs its map value. 1 is a round field (bats' fields in a
// flight room, Yartsev & Ulanovsky 2013); > 1 a column, < 1 a flat disc. NaN for cells with MI != 1
// (and for a field with no spread at all); +inf for a field with vertical spread only.
std::vector<double> field_isotropy(const Eigen::Ref<const Centers>& centers, const Eigen::Ref<const RowMatrixXd>& maps,
                                   const std::vector<int>& modality, const DbscanParams& params);

// The same for one field: points (N × 3) and their weights (> 0).
double isotropy_of(const Eigen::Ref<const Centers>& points, const Eigen::Ref<const Eigen::VectorXd>& weights);

}  // namespace bvc3d::analysis

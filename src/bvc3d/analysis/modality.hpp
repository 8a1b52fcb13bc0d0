#pragma once
// Modality index (docs/analysis.md): per cell, the number of clusters DBSCAN(eps, min_samples)
// finds among the centers of the bins where the cell's map is > 0, exactly as scikit-learn 1.2.1
// finds them, in any dimension.
// Takes: bin centers (N × D) and rate maps (bins × cells). Gives: one cluster count per cell and the
// paper's three summary figures.
#include <limits>
#include <span>
#include <vector>

#include "bvc3d/analysis/types.hpp"

namespace bvc3d::analysis {

struct DbscanParams {
    double eps = 1.0;      // m, neighborhood radius (distance <= eps)
    int min_samples = 20;  // neighbors, the point itself included, that make a core point
    void validate() const;
};

// Radius neighborhoods in compressed rows: the neighbors of point i are
// indices[offsets[i] .. offsets[i+1]), in no particular order.
struct Neighborhoods {
    std::vector<int> offsets{0};
    std::vector<int> indices;
};

// What NearestNeighbors(radius=eps).fit(X).radius_neighbors(X) returns in scikit-learn 1.2.1,
// which DBSCAN calls: for n <= 11 points the brute-force path (squared distance computed as
// |x|² − 2x·y + |y|², compared with eps²); otherwise its KD-tree (leaf_size 30), whose node-level
// tests (libm pow, distance to the node's box compared with eps) can accept a point that the
// point-level test (dx² + dy² <= eps²) would reject. Both are replicated, so points at exactly eps
// (a regular lattice) are classified as scikit-learn classifies them.
Neighborhoods sklearn_radius_neighbors(const Eigen::Ref<const Centers>& points, double eps);

// Number of clusters of DBSCAN(eps, min_samples).fit(points) (labels >= 0), by scikit-learn's own
// expansion order over its neighborhoods. 0 for no points (where scikit-learn would refuse).
int dbscan_cluster_count(const Eigen::Ref<const Centers>& points, const DbscanParams& params = {});

// The labels of DBSCAN(eps, min_samples).fit(points).labels_: per point its cluster (0, 1, ... in
// scikit-learn's numbering) or -1 for noise.
std::vector<int> dbscan_labels(const Eigen::Ref<const Centers>& points, const DbscanParams& params = {});

// Cluster count per cell (column of `maps`) over the centers of its bins with value > 0.
std::vector<int> modality(const Eigen::Ref<const Centers>& centers, const Eigen::Ref<const RowMatrixXd>& maps,
                          const DbscanParams& params = {});

// The paper's three figures. With no cells all are NaN; mean_mi_active is NaN when no cell has MI > 0.
struct ModalitySummary {
    double frac_active = std::numeric_limits<double>::quiet_NaN();      // MI > 0, fraction of all cells
    double mean_mi_active = std::numeric_limits<double>::quiet_NaN();   // mean MI over cells with MI > 0
    double frac_multimodal = std::numeric_limits<double>::quiet_NaN();  // MI > 1, fraction of all cells
};
ModalitySummary summarize_modality(std::span<const int> mi);

}  // namespace bvc3d::analysis

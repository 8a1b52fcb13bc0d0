#include "bvc3d/analysis/isotropy.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "bvc3d/core/error.hpp"

namespace bvc3d::analysis {

double isotropy_of(const Eigen::Ref<const Centers>& points, const Eigen::Ref<const Eigen::VectorXd>& weights) {
    if (points.cols() != 3)
        throw InputError("isotropy needs 3-D points, got " + std::to_string(points.cols()) + " columns");
    if (weights.size() != points.rows()) throw InputError("isotropy: one weight per point");
    const double total = weights.sum();
    if (!(total > 0)) return std::numeric_limits<double>::quiet_NaN();
    const Eigen::RowVector3d mean = (weights.transpose() * points) / total;
    double var[3] = {0, 0, 0};
    for (Eigen::Index i = 0; i < points.rows(); ++i)
        for (int d = 0; d < 3; ++d) var[d] += weights(i) * (points(i, d) - mean(d)) * (points(i, d) - mean(d));
    const double sx = std::sqrt(var[0] / total), sy = std::sqrt(var[1] / total), sz = std::sqrt(var[2] / total);
    const double across = 0.5 * (sx + sy);
    if (across > 0) return sz / across;
    return sz > 0 ? std::numeric_limits<double>::infinity() : std::numeric_limits<double>::quiet_NaN();
}

std::vector<double> field_isotropy(const Eigen::Ref<const Centers>& centers, const Eigen::Ref<const RowMatrixXd>& maps,
                                   const std::vector<int>& modality, const DbscanParams& params) {
    if (centers.cols() != 3)
        throw InputError("isotropy needs 3-D bin centers, got " + std::to_string(centers.cols()) + " columns");
    if (maps.rows() != centers.rows() || static_cast<std::size_t>(maps.cols()) != modality.size())
        throw InputError("isotropy: maps must be bins × cells with one modality index per cell");
    std::vector<double> out(modality.size(), std::numeric_limits<double>::quiet_NaN());
    Centers pts;
    Eigen::VectorXd w;
    for (Eigen::Index c = 0; c < maps.cols(); ++c) {
        if (modality[static_cast<std::size_t>(c)] != 1) continue;
        std::vector<Eigen::Index> active;
        for (Eigen::Index b = 0; b < maps.rows(); ++b)
            if (maps(b, c) > 0) active.push_back(b);
        pts.resize(static_cast<Eigen::Index>(active.size()), 3);
        for (std::size_t i = 0; i < active.size(); ++i) pts.row(static_cast<Eigen::Index>(i)) = centers.row(active[i]);
        const std::vector<int> label = dbscan_labels(pts, params);
        std::size_t n = 0;
        for (const int l : label) n += l == 0;
        Centers field(static_cast<Eigen::Index>(n), 3);
        w.resize(static_cast<Eigen::Index>(n));
        for (std::size_t i = 0, k = 0; i < active.size(); ++i)
            if (label[i] == 0) {
                field.row(static_cast<Eigen::Index>(k)) = pts.row(static_cast<Eigen::Index>(i));
                w(static_cast<Eigen::Index>(k++)) = maps(active[i], c);
            }
        out[static_cast<std::size_t>(c)] = isotropy_of(field, w);
    }
    return out;
}

}  // namespace bvc3d::analysis

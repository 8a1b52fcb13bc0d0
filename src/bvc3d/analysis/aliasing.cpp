#include "bvc3d/analysis/aliasing.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "bvc3d/analysis/point_grid.hpp"
#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d::analysis {

AliasingResult spatial_aliasing(const Eigen::Ref<const Centers>& centers, const Eigen::Ref<const RowMatrixXd>& maps,
                                double d_th) {
    if (!(d_th >= 0) || !std::isfinite(d_th))
        throw InputError("d_th must be a finite distance >= 0, got " + std::to_string(d_th));
    if (maps.rows() != centers.rows())
        throw InputError("maps must have one row per bin center: " + std::to_string(maps.rows()) + " rows for " +
                         std::to_string(centers.rows()) + " centers");
    if (centers.cols() < 1 || centers.cols() > 3)
        throw InputError("centers must have 1 to 3 coordinates, got " + std::to_string(centers.cols()));
    if (!centers.allFinite() || !maps.allFinite()) throw InputError("centers and maps must be finite");

    AliasingResult out;
    const Eigen::Index n_bins = maps.rows();
    out.sai = Eigen::VectorXd::Zero(n_bins);
    if (n_bins == 0) {
        out.msai = std::numeric_limits<double>::quiet_NaN();
        return out;
    }
    // Unit population vectors; a zero vector stays zero (its cosines are 0).
    RowMatrixXd unit = maps;
    std::vector<std::vector<int>> nonzero(static_cast<std::size_t>(n_bins));
    for (Eigen::Index i = 0; i < n_bins; ++i) {
        const double norm = unit.row(i).norm();
        if (norm > 0) unit.row(i) /= norm;
        for (Eigen::Index c = 0; c < unit.cols(); ++c)
            if (unit(i, c) != 0) nonzero[static_cast<std::size_t>(i)].push_back(static_cast<int>(c));
    }
    const Eigen::RowVectorXd total = unit.colwise().sum();
    const PointGrid grid(centers, d_th);
    for (Eigen::Index i = 0; i < n_bins; ++i) {
        if (i % 256 == 0) poll_cancel();
        const auto& nz = nonzero[static_cast<std::size_t>(i)];
        if (nz.empty()) continue;
        const auto ai = unit.row(i);
        double all = 0;
        for (const int c : nz) all += ai(c) * total(c);
        double near = 0;
        grid.for_each_candidate(centers.row(i).data(), [&](int j) {
            double d2 = 0;
            for (Eigen::Index d = 0; d < centers.cols(); ++d) {
                const double diff = centers(i, d) - centers(j, d);
                d2 += diff * diff;
            }
            if (std::sqrt(d2) > d_th) return;
            const auto aj = unit.row(j);
            for (const int c : nz) near += ai(c) * aj(c);
        });
        out.sai(i) = (all - near) / static_cast<double>(n_bins);
    }
    out.msai = out.sai.mean();
    return out;
}

}  // namespace bvc3d::analysis

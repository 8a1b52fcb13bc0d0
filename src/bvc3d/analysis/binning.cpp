#include "bvc3d/analysis/binning.hpp"

#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"

namespace bvc3d::analysis {

void check_positions(const Eigen::Ref<const Points>& positions, int dims) {
    if (dims > 0 && positions.cols() != dims)
        throw InputError("positions must have " + std::to_string(dims) + " coordinates per sample, got " +
                         std::to_string(positions.cols()));
    for (Eigen::Index i = 0; i < positions.rows(); ++i)
        if (!positions.row(i).allFinite()) {
            std::string p;
            for (Eigen::Index d = 0; d < positions.cols(); ++d) p += (d ? ", " : "") + std::to_string(positions(i, d));
            throw InputError("positions must be finite: sample " + std::to_string(i) + " is (" + p + ")");
        }
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

Points positions_2d(std::span<const double> x, std::span<const double> y) {
    if (x.size() != y.size())
        throw InputError("x and y must have the same length, got " + std::to_string(x.size()) + " and " +
                         std::to_string(y.size()));
    Points p(static_cast<Eigen::Index>(x.size()), 2);
    for (std::size_t i = 0; i < x.size(); ++i) {
        p(static_cast<Eigen::Index>(i), 0) = x[i];
        p(static_cast<Eigen::Index>(i), 1) = y[i];
    }
    return p;
}

Bins bin_positions(const Grid& grid, const Eigen::Ref<const Points>& positions) {
    check_positions(positions, grid.dims());
    Bins out;
    const std::size_t n = static_cast<std::size_t>(positions.rows());
    std::vector<int> flat(n);
    std::vector<std::int64_t> count(static_cast<std::size_t>(grid.size()), 0);
    for (std::size_t i = 0; i < n; ++i) {
        flat[i] = grid.bin_of(positions.row(static_cast<Eigen::Index>(i)).data());
        if (flat[i] >= 0) ++count[static_cast<std::size_t>(flat[i])];
    }
    // Only visited bins exist (matplotlib turns empty bins into NaN and removes them).
    std::vector<int> row_of(count.size(), -1);
    for (int b = 0; b < grid.size(); ++b)
        if (count[static_cast<std::size_t>(b)] > 0) {
            row_of[static_cast<std::size_t>(b)] = static_cast<int>(out.ids.size());
            out.ids.push_back(b);
            out.counts.push_back(count[static_cast<std::size_t>(b)]);
        }
    out.centers.resize(static_cast<Eigen::Index>(out.ids.size()), grid.dims());
    for (std::size_t r = 0; r < out.ids.size(); ++r)
        grid.center(out.ids[r], out.centers.row(static_cast<Eigen::Index>(r)).data());
    out.sample_bin.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        out.sample_bin[i] = flat[i] < 0 ? -1 : row_of[static_cast<std::size_t>(flat[i])];
    return out;
}

template <class T>
RowMatrixXd bin_means(const Bins& bins, const Eigen::Ref<const RowMatrixX<T>>& values) {
    check_values<T>(values, bins.sample_bin.size(), "values");
    RowMatrixXd sum = RowMatrixXd::Zero(bins.size(), values.cols());
    for (std::size_t i = 0; i < bins.sample_bin.size(); ++i)
        if (const int b = bins.sample_bin[i]; b >= 0)
            sum.row(b) += values.row(static_cast<Eigen::Index>(i)).template cast<double>();
    for (int b = 0; b < bins.size(); ++b) sum.row(b) /= static_cast<double>(bins.counts[static_cast<std::size_t>(b)]);
    return sum;
}

template RowMatrixXd bin_means<float>(const Bins&, const Eigen::Ref<const RowMatrixXf>&);
template RowMatrixXd bin_means<double>(const Bins&, const Eigen::Ref<const RowMatrixXd>&);
template void check_values<float>(const Eigen::Ref<const RowMatrixXf>&, std::size_t, const char*);
template void check_values<double>(const Eigen::Ref<const RowMatrixXd>&, std::size_t, const char*);

}  // namespace bvc3d::analysis

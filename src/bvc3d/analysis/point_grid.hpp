#pragma once
// A uniform grid over points of any dimension for fixed-radius queries (internal to the analysis
// stage). Cells are cubes of side >= radius, so a query looks at the 3^D cells around a point.
#include <algorithm>
#include <cmath>
#include <vector>

#include "bvc3d/analysis/types.hpp"

namespace bvc3d::analysis {

class PointGrid {
public:
    PointGrid(const Eigen::Ref<const Points>& pts, double radius) : dims_(static_cast<int>(pts.cols())) {
        const Eigen::Index n = pts.rows();
        if (n == 0 || dims_ == 0) return;
        origin_ = pts.colwise().minCoeff().transpose();
        const double span = (pts.colwise().maxCoeff().transpose() - origin_).maxCoeff();
        const double per_axis = dims_ <= 2 ? 1024.0 : 128.0;  // at most ~1e6 cells
        h_ = std::max({radius, span / per_axis, 1e-300});
        n_ = static_cast<int>(std::min(span / h_, per_axis)) + 1;
        std::size_t cells = 1;
        for (int d = 0; d < dims_; ++d) cells *= static_cast<std::size_t>(n_);
        start_.assign(cells + 1, 0);
        std::vector<std::size_t> cell(static_cast<std::size_t>(n));
        for (Eigen::Index i = 0; i < n; ++i) {
            cell[static_cast<std::size_t>(i)] = cell_of(pts.row(i).data());
            ++start_[cell[static_cast<std::size_t>(i)] + 1];
        }
        for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
        items_.resize(static_cast<std::size_t>(n));
        std::vector<int> fill(start_.begin(), start_.end() - 1);
        for (Eigen::Index i = 0; i < n; ++i)
            items_[static_cast<std::size_t>(fill[cell[static_cast<std::size_t>(i)]]++)] = static_cast<int>(i);
    }

    // Calls f(j) for every point j in the cells around `p` (dims coordinates): a superset of those
    // within radius.
    template <class F>
    void for_each_candidate(const double* p, F&& f) const {
        if (items_.empty()) return;
        int lo[3], hi[3], at[3];
        for (int d = 0; d < dims_; ++d) {
            const int c = clamp_cell((p[d] - origin_(d)) / h_);
            lo[d] = std::max(c - 1, 0);
            hi[d] = std::min(c + 1, n_ - 1);
            at[d] = lo[d];
        }
        for (;;) {
            std::size_t c = 0;
            for (int d = 0; d < dims_; ++d) c = c * static_cast<std::size_t>(n_) + static_cast<std::size_t>(at[d]);
            for (int k = start_[c]; k < start_[c + 1]; ++k) f(items_[static_cast<std::size_t>(k)]);
            int d = dims_ - 1;  // next cell, last coordinate fastest
            while (d >= 0 && at[d] == hi[d]) at[d] = lo[d], --d;
            if (d < 0) return;
            ++at[d];
        }
    }

private:
    int clamp_cell(double u) const { return static_cast<int>(std::clamp(std::floor(u), 0.0, n_ - 1.0)); }
    std::size_t cell_of(const double* p) const {
        std::size_t c = 0;
        for (int d = 0; d < dims_; ++d)
            c = c * static_cast<std::size_t>(n_) + static_cast<std::size_t>(clamp_cell((p[d] - origin_(d)) / h_));
        return c;
    }

    int dims_;
    Eigen::VectorXd origin_;
    double h_ = 1;
    int n_ = 0;  // cells per axis
    std::vector<int> start_, items_;
};

}  // namespace bvc3d::analysis

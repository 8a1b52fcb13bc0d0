#pragma once
// A uniform grid over 2-D points for fixed-radius queries (internal to the analysis stage).
#include <algorithm>
#include <cmath>
#include <vector>

#include "bvc3d/analysis/types.hpp"

namespace bvc3d::analysis {

class PointGrid {
public:
    // Cells are squares of side >= radius, so a query looks at the 3 × 3 cells around a point.
    PointGrid(const Eigen::Ref<const Centers>& pts, double radius) {
        const Eigen::Index n = pts.rows();
        if (n == 0) return;
        x0_ = pts.col(0).minCoeff(), y0_ = pts.col(1).minCoeff();
        const double span = std::max(pts.col(0).maxCoeff() - x0_, pts.col(1).maxCoeff() - y0_);
        h_ = std::max({radius, span / 1024, 1e-300});  // at most ~1024² cells
        nx_ = static_cast<int>(std::min(span / h_, 1024.0)) + 1;
        ny_ = nx_;
        start_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_) + 1, 0);
        std::vector<int> cell(static_cast<std::size_t>(n));
        for (Eigen::Index i = 0; i < n; ++i) {
            cell[static_cast<std::size_t>(i)] = cell_of(pts(i, 0), pts(i, 1));
            ++start_[static_cast<std::size_t>(cell[static_cast<std::size_t>(i)]) + 1];
        }
        for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
        items_.resize(static_cast<std::size_t>(n));
        std::vector<int> fill(start_.begin(), start_.end() - 1);
        for (Eigen::Index i = 0; i < n; ++i)
            items_[static_cast<std::size_t>(fill[static_cast<std::size_t>(cell[static_cast<std::size_t>(i)])]++)] =
                static_cast<int>(i);
    }

    // Calls f(j) for every point j in the cells around (x, y): a superset of those within radius.
    template <class F>
    void for_each_candidate(double x, double y, F&& f) const {
        if (items_.empty()) return;
        const int cx = clamp_cell((x - x0_) / h_, nx_), cy = clamp_cell((y - y0_) / h_, ny_);
        for (int i = std::max(cx - 1, 0); i <= std::min(cx + 1, nx_ - 1); ++i)
            for (int j = std::max(cy - 1, 0); j <= std::min(cy + 1, ny_ - 1); ++j) {
                const std::size_t c = static_cast<std::size_t>(i) * static_cast<std::size_t>(ny_) + static_cast<std::size_t>(j);
                for (int k = start_[c]; k < start_[c + 1]; ++k) f(items_[static_cast<std::size_t>(k)]);
            }
    }

private:
    static int clamp_cell(double u, int n) { return static_cast<int>(std::clamp(std::floor(u), 0.0, n - 1.0)); }
    int cell_of(double x, double y) const { return clamp_cell((x - x0_) / h_, nx_) * ny_ + clamp_cell((y - y0_) / h_, ny_); }

    double x0_ = 0, y0_ = 0, h_ = 1;
    int nx_ = 0, ny_ = 0;
    std::vector<int> start_, items_;
};

}  // namespace bvc3d::analysis

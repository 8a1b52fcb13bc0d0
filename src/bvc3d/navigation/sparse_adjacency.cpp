#include "bvc3d/navigation/sparse_adjacency.hpp"

#include <algorithm>
#include <cmath>

#include "bvc3d/navigation/adjacency_kernels.hpp"

namespace bvc3d {

SparseAdjacency::SparseAdjacency(const HdAdjacency& adj, double prune)
    : n_(adj.n_),
      scale_(adj.scale_),
      antisymmetric_(adj.antisymmetric_),
      pruned_(prune > 0),
      rows_(std::size_t(adj.p_.n_hd)) {
    const auto kept = adj.kept(prune, "sparse");
    for (int k = 0; k < adj.p_.n_hd; ++k) {
        const float* m = &adj.m_[adj.index(k, 0, 0)];
        const float cut = kept.cut[std::size_t(k)];
        Rows& r = rows_[std::size_t(k)];
        r.start.assign(std::size_t(n_) + 1, 0);
        for (int i = 0; i < n_; ++i) {
            const float* row = m + std::size_t(i) * std::size_t(n_);
            for (int j = 0; j < n_; ++j)
                if (std::abs(row[j]) > cut) r.col.push_back(std::uint16_t(j)), r.w.push_back(row[j]);
            r.start[std::size_t(i) + 1] = std::uint32_t(r.col.size());
        }
    }
}

void SparseAdjacency::apply(int k, std::span<const double> x, std::span<double> out) const {
    // Unpruned: the same two forms, in the same order, as HdAdjacency::apply (a left-out weight only adds ±0 there).
    // A pruned copy's bits are its own: the column form where it reads under a third of the entries (a rollout's
    // first step, from the place cells' rates), else every row in 16 lanes (kernels::row_sums16, gathers: faster
    // per entry than the column form's scattered updates, docs/performance.md; after a rollout step ~all cells are on).
    const Rows& r = rows_[std::size_t(k)];
    std::size_t active = 0, work = 0;
    for (std::size_t j = 0; j < x.size(); ++j)
        if (x[j] != 0.0) ++active, work += r.start[j + 1] - r.start[j];
    if (pruned_ && !by_columns(antisymmetric_, work, r.col.size())) {
        kernels::row_sums16(r.start.data(), r.col.data(), r.w.data(), n_, x.data(), scale_, out.data());
        return;
    }
    if (antisymmetric_ && (pruned_ || 4 * active < std::size_t(n_))) {
        std::fill(out.begin(), out.end(), 0.0);
        for (int j = 0; j < n_; ++j) {
            const double xj = x[std::size_t(j)];
            if (xj == 0.0) continue;
            for (std::uint32_t e = r.start[std::size_t(j)]; e < r.start[std::size_t(j) + 1]; ++e)
                out[r.col[e]] -= xj * double(r.w[e]);
        }
        for (double& o : out) o *= scale_;
        return;
    }
    for (int i = 0; i < n_; ++i) {
        double sum = 0.0;
        for (std::uint32_t e = r.start[std::size_t(i)]; e < r.start[std::size_t(i) + 1]; ++e)
            sum += double(r.w[e]) * x[r.col[e]];
        out[std::size_t(i)] = scale_ * sum;
    }
}

std::vector<double> SparseAdjacency::column_sums() const {
    std::vector<double> c(rows_.size() * std::size_t(n_), 0.0);
    for (std::size_t k = 0; k < rows_.size(); ++k) {
        double* ck = &c[k * std::size_t(n_)];
        for (std::size_t e = 0; e < rows_[k].col.size(); ++e) ck[rows_[k].col[e]] += double(rows_[k].w[e]);
        for (int j = 0; j < n_; ++j) ck[j] *= scale_;
    }
    return c;
}

std::size_t SparseAdjacency::entries() const {
    std::size_t e = 0;
    for (const Rows& r : rows_) e += r.col.size();
    return e;
}

double SparseAdjacency::bytes() const {
    return double(entries()) * (sizeof(std::uint16_t) + sizeof(float)) +
           double(rows_.size()) * double(n_ + 1) * sizeof(std::uint32_t);
}

}  // namespace bvc3d

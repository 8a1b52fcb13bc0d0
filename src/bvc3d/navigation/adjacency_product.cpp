#include "bvc3d/navigation/adjacency_product.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"
#include "bvc3d/navigation/packed_adjacency.hpp"
#include "bvc3d/navigation/sparse_adjacency.hpp"

namespace bvc3d {

void AdjacencyProduct::check(std::size_t x, std::size_t y, std::size_t which) const {
    const auto n = std::size_t(n_place()), K = std::size_t(n_dir());
    if (x != n * K || y != n * K)
        throw InputError("adjacency product: states of " + std::to_string(x) + " and " + std::to_string(y) +
                         " values for " + std::to_string(n) + " cells × " + std::to_string(K) + " directions");
    if (which != 0 && which != K)
        throw InputError("adjacency product: " + std::to_string(which) + " direction flags for " + std::to_string(K) +
                         " directions");
}

void AdjacencyProduct::apply(std::span<const double> X, std::span<double> Y, std::span<const char> which) const {
    check(X.size(), Y.size(), which.size());
    const auto n = std::size_t(n_place()), K = std::size_t(n_dir());
    std::vector<double> x(n), y(n);
    for (std::size_t k = 0; k < K; ++k) {
        if (!which.empty() && !which[k]) {
            for (std::size_t i = 0; i < n; ++i) Y[i * K + k] = 0.0;
            continue;
        }
        for (std::size_t j = 0; j < n; ++j) x[j] = X[j * K + k];
        apply_one(static_cast<int>(k), x, y);
        for (std::size_t i = 0; i < n; ++i) Y[i * K + k] = y[i];
    }
}

void AdjacencyProduct::apply(std::span<const float> X, std::span<float> Y, std::span<const char> which) const {
    check(X.size(), Y.size(), which.size());
    std::vector<double> x(X.begin(), X.end()), y(Y.size());
    apply(x, y, which);
    std::transform(y.begin(), y.end(), Y.begin(), [](double v) { return static_cast<float>(v); });
}

void AdjacencyProduct::apply_one(int, std::span<const double>, std::span<double>) const {
    throw std::logic_error("adjacency product: a copy must give apply_one or both apply forms");
}

ReferenceAdjacency::ReferenceAdjacency(const HdAdjacency& adj, double prune) : n_(adj.n_), n_dir_(adj.p_.n_hd) {
    const auto kept = adj.kept(prune, "reference");
    w_.assign(adj.m_.size(), 0.0);
    for (std::size_t e = 0; e < w_.size(); ++e) {
        const float m = adj.m_[e];
        if (std::abs(m) <= kept.cut[e / (std::size_t(n_) * std::size_t(n_))]) continue;
        w_[e] = adj.scale_ * double(m);
        ++entries_;
    }
}

void ReferenceAdjacency::apply_one(int k, std::span<const double> x, std::span<double> y) const {
    const auto n = std::size_t(n_);
    const double* w = &w_[std::size_t(k) * n * n];
    for (std::size_t i = 0; i < n; ++i) {
        double sum = 0.0;
        for (std::size_t j = 0; j < n; ++j) sum += w[i * n + j] * x[j];
        y[i] = sum;
    }
}

std::unique_ptr<AdjacencyProduct> make_rollout_product(const HdAdjacency& adj, const AdjacencyParams& params) {
    if (params.rollout_weights == RolloutWeights::float16) return std::make_unique<PackedAdjacency>(adj, params.prune);
    return std::make_unique<SparseAdjacency>(adj, params.prune);
}

}  // namespace bvc3d

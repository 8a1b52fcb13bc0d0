#include "bvc3d/navigation/packed_adjacency.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"
#include "bvc3d/navigation/adjacency_kernels.hpp"
#include "bvc3d/navigation/sparse_adjacency.hpp"

namespace bvc3d {

PackedAdjacency::PackedAdjacency(const HdAdjacency& adj, double prune, int panel)
    : n_(adj.n_), n_hd_(adj.p_.n_hd), antisymmetric_(adj.antisymmetric_), tiles_(pack(adj, prune, panel)) {}

std::shared_ptr<const kernels::HalfTiles> PackedAdjacency::pack(const HdAdjacency& adj, double prune, int panel) {
    const auto [top, cut] = adj.kept(prune, "packed");
    const auto n = std::size_t(n_), K = std::size_t(n_hd_);
    for (std::size_t k = 0; k < K; ++k) factor_.push_back(static_cast<float>(adj.scale_ * double(top[k])));
    std::vector<std::uint32_t> start{0};
    std::vector<std::uint16_t> col, half;
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = 0; j < n; ++j) {
            bool kept = false;
            for (std::size_t k = 0; k < K; ++k)
                kept = kept || std::abs(adj.m_[adj.index(int(k), int(i), int(j))]) > cut[k];
            if (!kept) continue;
            col.push_back(std::uint16_t(j));
            for (std::size_t k = 0; k < K; ++k) {
                const float w = adj.m_[adj.index(int(k), int(i), int(j))];
                const Eigen::half h(std::abs(w) > cut[k] ? w / top[k] : 0.0f);
                half.push_back(Eigen::numext::bit_cast<std::uint16_t>(h));
            }
        }
        start.push_back(std::uint32_t(col.size()));
        row_entries_.push_back(start[i + 1] - start[i]);
    }
    return std::make_shared<const kernels::HalfTiles>(start.data(), col.data(), half.data(), n_, n_hd_, 64, panel);
}

void PackedAdjacency::apply(std::span<const float> x, std::span<float> y, std::span<const char> which) const {
    const auto K = std::size_t(n_hd_);
    check(x.size(), y.size(), which.size());
    std::size_t work = 0;
    for (std::size_t j = 0; j < std::size_t(n_); ++j)
        if (std::any_of(&x[j * K], &x[j * K] + K, [](float v) { return v != 0.0f; })) work += row_entries_[j];
    if (by_columns(antisymmetric_, work, entries())) kernels::half_columns(*tiles_, x.data(), factor_.data(), y.data());
    else kernels::half_rows(*tiles_, x.data(), factor_.data(), y.data());
}

void PackedAdjacency::apply(std::span<const double> X, std::span<double> Y, std::span<const char> which) const {
    check(X.size(), Y.size(), which.size());
    std::vector<float> x(X.begin(), X.end()), y(Y.size());
    apply(x, y, which);
    std::copy(y.begin(), y.end(), Y.begin());
}

std::size_t PackedAdjacency::entries() const { return tiles_->col.size(); }

double PackedAdjacency::bytes() const {
    return double(tiles_->col.size() + tiles_->h.size()) * sizeof(std::uint16_t) +
           double(tiles_->start.size()) * sizeof(std::uint32_t) + double(tiles_->phase.size());
}

}  // namespace bvc3d

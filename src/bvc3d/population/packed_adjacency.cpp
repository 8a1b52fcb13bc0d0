#include "bvc3d/population/packed_adjacency.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"
#include "bvc3d/population/adjacency_kernels.hpp"

namespace bvc3d {

PackedAdjacency::PackedAdjacency(const HdAdjacency& adj, double prune)
    : n_(adj.n_), n_hd_(adj.p_.n_hd), antisymmetric_(adj.antisymmetric_), start_(std::size_t(adj.n_) + 1, 0) {
    const auto [top, cut] = adj.kept(prune, "packed");
    const auto n = std::size_t(n_), K = std::size_t(n_hd_);
    for (std::size_t k = 0; k < K; ++k) factor_.push_back(static_cast<float>(adj.scale_ * double(top[k])));
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = 0; j < n; ++j) {
            bool kept = false;
            for (std::size_t k = 0; k < K; ++k)
                kept = kept || std::abs(adj.m_[adj.index(int(k), int(i), int(j))]) > cut[k];
            if (!kept) continue;
            col_.push_back(std::uint16_t(j));
            for (std::size_t k = 0; k < K; ++k) {
                const float w = adj.m_[adj.index(int(k), int(i), int(j))];
                const Eigen::half h(std::abs(w) > cut[k] ? w / top[k] : 0.0f);
                half_.push_back(Eigen::numext::bit_cast<std::uint16_t>(h));
            }
        }
        start_[i + 1] = std::uint32_t(col_.size());
    }
}

void PackedAdjacency::apply(std::span<const float> x, std::span<float> y) const {
    const auto K = std::size_t(n_hd_);
    if (x.size() != std::size_t(n_) * K || y.size() != x.size())
        throw InputError("PackedAdjacency: states of " + std::to_string(x.size()) + " and " + std::to_string(y.size()) +
                         " values for " + std::to_string(n_) + " cells × " + std::to_string(K) + " directions");
    std::size_t work = 0;
    for (std::size_t j = 0; j < std::size_t(n_); ++j)
        if (std::any_of(&x[j * K], &x[j * K] + K, [](float v) { return v != 0.0f; })) work += start_[j + 1] - start_[j];
    if (by_columns(antisymmetric_, work, col_.size()))
        kernels::half_columns(start_.data(), col_.data(), half_.data(), n_, n_hd_, x.data(), factor_.data(), y.data());
    else kernels::half_rows(start_.data(), col_.data(), half_.data(), n_, n_hd_, x.data(), factor_.data(), y.data());
}

double PackedAdjacency::bytes() const {
    return double(col_.size()) * sizeof(std::uint16_t) + double(half_.size()) * sizeof(std::uint16_t) +
           double(start_.size()) * sizeof(std::uint32_t);
}

}  // namespace bvc3d

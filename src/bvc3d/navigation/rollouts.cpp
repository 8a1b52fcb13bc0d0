#include "bvc3d/navigation/rollouts.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/vector_math.hpp"
#include "bvc3d/navigation/sparse_adjacency.hpp"

namespace bvc3d {

namespace {

// The rollouts with states of type S between steps (the copy's precision); sums and the read-out in double.
template <class S>
std::vector<double> rollouts(const AdjacencyProduct& adj, std::span<const double> w, std::span<const double> v,
                             const RewardParams& p, std::span<const char> offered) {
    const auto n = std::size_t(adj.n_place()), K = std::size_t(adj.n_dir());
    if (!offered.empty() && offered.size() != K)
        throw InputError("direction_returns: " + std::to_string(offered.size()) + " flags for " + std::to_string(K) +
                         " directions");
    if (v.size() != n || w.size() != n)
        throw InputError("direction_returns: " + std::to_string(v.size()) + " rates and " + std::to_string(w.size()) +
                         " weights for " + std::to_string(n) + " place cells");
    std::vector<double> out(K, 0.0), z(n * K), dot(K), l1(K);
    std::vector<S> x(n * K), y(n * K);
    for (std::size_t i = 0; i < n; ++i) std::fill_n(&x[i * K], K, static_cast<S>(v[i]));
    double g = 1.0;
    for (int t = 0; t < p.rollout_steps; ++t) {
        adj.apply(std::span<const S>(x), std::span<S>(y), offered);
        for (std::size_t e = 0; e < n * K; ++e) z[e] = std::max(double(y[e]) - double(x[e]), 0.0);
        vector_tanh(z.data(), z.data(), n * K);
        // r(x) per direction, as reward(): the cells in order.
        std::fill(dot.begin(), dot.end(), 0.0), std::fill(l1.begin(), l1.end(), 0.0);
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t k = 0; k < K; ++k) dot[k] += w[i] * z[i * K + k], l1[k] += std::abs(z[i * K + k]);
        for (std::size_t k = 0; k < K; ++k)
            if (offered.empty() || offered[k]) out[k] += g * (dot[k] / std::max(l1[k], 1e-4));
        for (std::size_t e = 0; e < n * K; ++e) x[e] = static_cast<S>(z[e]);
        g *= p.discount;
    }
    return out;
}

}  // namespace

std::vector<double> direction_returns(const AdjacencyProduct& adj, std::span<const double> w, std::span<const double> v,
                                      const RewardParams& p, std::span<const char> offered) {
    return adj.precision() == StatePrecision::float32 ? rollouts<float>(adj, w, v, p, offered)
                                                      : rollouts<double>(adj, w, v, p, offered);
}

std::vector<double> direction_returns(const HdAdjacency& adj, std::span<const double> w, std::span<const double> v,
                                      const RewardParams& p) {
    return direction_returns(SparseAdjacency(adj), w, v, p);
}

}  // namespace bvc3d

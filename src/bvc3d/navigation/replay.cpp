#include "bvc3d/navigation/replay.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"
#include "bvc3d/navigation/sparse_adjacency.hpp"
#include "bvc3d/population/reward_cells.hpp"

namespace bvc3d {

std::vector<double> replay(const HdAdjacency& adj, int goal_cell, const RewardParams& p) {
    return replay(SparseAdjacency(adj), goal_cell, p);
}

std::vector<double> replay(const AdjacencyProduct& adj, int goal_cell, const RewardParams& p) {
    const auto n = std::size_t(adj.n_place()), K = std::size_t(adj.n_dir());
    if (goal_cell < 0 || std::size_t(goal_cell) >= n)
        throw InputError("replay: goal cell " + std::to_string(goal_cell) + " is not one of " + std::to_string(n));
    std::vector<double> w(n, 0.0), x(n, 0.0), X(n * K), Y(n * K);
    x[std::size_t(goal_cell)] = 1.0;
    const double amp = p.amplitude_or_default();
    const int steps = static_cast<int>(std::ceil(8 * p.lambda));
    for (int t = 0; t <= steps; ++t) {
        double norm = 0.0;
        for (double v : x) norm += v * v;
        norm = std::sqrt(norm);
        if (norm == 0.0) break;
        const double c = amp * std::exp(-t / p.lambda) / norm;
        for (std::size_t i = 0; i < n; ++i) w[i] += c * x[i];
        // Every direction's matrix times the same x; the largest of each cell's sums.
        for (std::size_t i = 0; i < n; ++i) std::fill_n(&X[i * K], K, x[i]);
        adj.apply(std::span<const double>(X), std::span<double>(Y));
        for (std::size_t i = 0; i < n; ++i) {
            const double best = *std::max_element(&Y[i * K], &Y[i * K] + K);
            x[i] = std::tanh(std::max(best + x[i], 0.0));
        }
    }
    return w;
}

double reward(std::span<const double> w, std::span<const double> v) { return reward_readout(w, v); }

}  // namespace bvc3d

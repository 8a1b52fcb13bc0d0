#include "bvc3d/population/reward_cells.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

const params::Table<RewardParams>& RewardParams::table() {
    using namespace params;
    static const Table<RewardParams> t(
        "reward",
        {real("lambda", &RewardParams::lambda, closed(0.1, 1e4), "λ of replay: ⌈8λ⌉ + 1 steps decaying as e^{−t/λ}"),
         real("amplitude", &RewardParams::amplitude, closed(0, 1e6), "A of replay; 0: 5/λ"),
         integer("rollout_steps", &RewardParams::rollout_steps, closed(1, 100), "steps of each direction's rollout"),
         real("discount", &RewardParams::discount, closed(0, 1), "γ of the rollout's return"),
         real("beta", &RewardParams::beta, closed(0, 1e6), "directions are preferred by softmax(β·R)")});
    return t;
}

std::vector<double> replay(const HdAdjacency& adj, int goal_cell, const RewardParams& p) {
    return replay(SparseAdjacency(adj), goal_cell, p);
}

std::vector<double> replay(const SparseAdjacency& adj, int goal_cell, const RewardParams& p) {
    const auto n = std::size_t(adj.n_place());
    if (goal_cell < 0 || std::size_t(goal_cell) >= n)
        throw InputError("replay: goal cell " + std::to_string(goal_cell) + " is not one of " + std::to_string(n));
    std::vector<double> w(n, 0.0), x(n, 0.0), y(n), best(n);
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
        std::fill(best.begin(), best.end(), -std::numeric_limits<double>::infinity());
        for (int k = 0; k < adj.n_hd(); ++k) {
            adj.apply(k, x, y);
            for (std::size_t i = 0; i < n; ++i) best[i] = std::max(best[i], y[i]);
        }
        for (std::size_t i = 0; i < n; ++i) x[i] = std::tanh(std::max(best[i] + x[i], 0.0));
    }
    return w;
}

double reward(std::span<const double> w, std::span<const double> v) {
    double dot = 0.0, l1 = 0.0;
    for (std::size_t i = 0; i < v.size(); ++i) dot += w[i] * v[i], l1 += std::abs(v[i]);
    return dot / std::max(l1, 1e-4);
}

std::vector<double> direction_returns(const HdAdjacency& adj, std::span<const double> w, std::span<const double> v,
                                      const RewardParams& p) {
    return direction_returns(SparseAdjacency(adj), w, v, p);
}

std::vector<double> direction_returns(const SparseAdjacency& adj, std::span<const double> w, std::span<const double> v,
                                      const RewardParams& p) {
    const auto n = std::size_t(adj.n_place());
    std::vector<double> out(std::size_t(adj.n_hd()), 0.0), x(n), y(n);
    for (int k = 0; k < adj.n_hd(); ++k) {
        x.assign(v.begin(), v.end());
        double g = 1.0;
        for (int t = 0; t < p.rollout_steps; ++t) {
            adj.apply(k, x, y);
            for (std::size_t i = 0; i < n; ++i) x[i] = std::tanh(std::max(y[i] - x[i], 0.0));
            out[std::size_t(k)] += g * reward(w, x);
            g *= p.discount;
        }
    }
    return out;
}

std::vector<double> softmax(std::span<const double> values, double beta, const std::vector<char>& allowed) {
    std::vector<double> p(values.size(), 0.0);
    double top = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < values.size(); ++i)
        if (allowed[i]) top = std::max(top, beta * values[i]);
    if (!std::isfinite(top)) return p;
    double sum = 0.0;
    for (std::size_t i = 0; i < values.size(); ++i)
        if (allowed[i]) sum += p[i] = std::exp(beta * values[i] - top);
    for (double& q : p) q /= sum;
    return p;
}

}  // namespace bvc3d

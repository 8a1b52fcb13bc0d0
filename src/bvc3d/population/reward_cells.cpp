#include "bvc3d/population/reward_cells.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/vector_math.hpp"

namespace bvc3d {

const params::Table<RewardParams>& RewardParams::table() {
    using namespace params;
    static const Table<RewardParams> t(
        "reward",
        {real("lambda", &RewardParams::lambda, closed(0.1, 1e4), "λ of replay: ⌈8λ⌉ + 1 steps decaying as e^{−t/λ}"),
         real("amplitude", &RewardParams::amplitude, closed(0, 1e6), "A of replay; 0: 5/λ"),
         integer("rollout_steps", &RewardParams::rollout_steps, closed(1, 100), "steps of each direction's rollout"),
         real("discount", &RewardParams::discount, closed(0, 1), "γ of the rollout's return"),
         real("beta", &RewardParams::beta, closed(0, 1e6), "directions are preferred by softmax(β·R)"),
         reals("scale_lambdas", &RewardParams::scale_lambdas, closed(0.1, 1e4),
               "λ of a multiscale model's second, third, ... scale (the first takes lambda)")
             .quiet_at_default(),
         real("scale_beta", &RewardParams::scale_beta, closed(0, 1e6), "scales are weighted by softmax(β·score)")
             .quiet_at_default(),
         real("scale_smoothing", &RewardParams::scale_smoothing, closed(0, 1),
              "a scale's score = mean return / entropy, averaged over decisions with this weight on the newest")
             .quiet_at_default()});
    return t;
}

RewardParams RewardParams::for_scale(std::size_t s) const {
    RewardParams p = *this;
    if (s == 0) return p;
    if (s > scale_lambdas.size())
        table().fail("scale_lambdas",
                     "gives λ for " + std::to_string(scale_lambdas.size() + 1) + " scales, but the model has more");
    p.lambda = scale_lambdas[s - 1];
    return p;
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

namespace {

// `offered`: empty (every direction) or one flag per direction.
void check_offered(std::span<const char> offered, std::size_t directions) {
    if (!offered.empty() && offered.size() != directions)
        throw InputError("direction_returns: " + std::to_string(offered.size()) + " flags for " +
                         std::to_string(directions) + " directions");
}

}  // namespace

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
                                      const RewardParams& p, std::span<const char> offered) {
    const auto n = std::size_t(adj.n_place());
    check_offered(offered, std::size_t(adj.n_hd()));
    std::vector<double> out(std::size_t(adj.n_hd()), 0.0), x(n), y(n);
    for (int k = 0; k < adj.n_hd(); ++k) {
        if (!offered.empty() && !offered[std::size_t(k)]) continue;
        x.assign(v.begin(), v.end());
        double g = 1.0;
        for (int t = 0; t < p.rollout_steps; ++t) {
            adj.apply(k, x, y);
            for (std::size_t i = 0; i < n; ++i) x[i] = std::max(y[i] - x[i], 0.0);
            vector_tanh(x.data(), x.data(), n);
            out[std::size_t(k)] += g * reward(w, x);
            g *= p.discount;
        }
    }
    return out;
}

std::vector<double> direction_returns(const PackedAdjacency& adj, std::span<const double> w, std::span<const double> v,
                                      const RewardParams& p, std::span<const char> offered) {
    const auto n = std::size_t(adj.n_place()), K = std::size_t(adj.n_hd());
    check_offered(offered, K);
    std::vector<double> out(K, 0.0), z(n * K), dot(K), l1(K);
    std::vector<float> x(n * K), y(n * K);
    for (std::size_t i = 0; i < n; ++i) std::fill_n(&x[i * K], K, static_cast<float>(v[i]));
    double g = 1.0;
    for (int t = 0; t < p.rollout_steps; ++t) {
        adj.apply(x, y);
        for (std::size_t e = 0; e < n * K; ++e) z[e] = std::max(double(y[e]) - double(x[e]), 0.0);
        vector_tanh(z.data(), z.data(), n * K);
        // r(x) per direction, as reward(): the cells in order.
        std::fill(dot.begin(), dot.end(), 0.0), std::fill(l1.begin(), l1.end(), 0.0);
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t k = 0; k < K; ++k) dot[k] += w[i] * z[i * K + k], l1[k] += std::abs(z[i * K + k]);
        for (std::size_t k = 0; k < K; ++k)
            if (offered.empty() || offered[k]) out[k] += g * (dot[k] / std::max(l1[k], 1e-4));
        for (std::size_t e = 0; e < n * K; ++e) x[e] = static_cast<float>(z[e]);
        g *= p.discount;
    }
    return out;
}

std::vector<double> combine_scales(const std::vector<std::vector<double>>& returns, const std::vector<char>& allowed,
                                   const RewardParams& p, std::vector<double>& scores) {
    const std::size_t n_scales = returns.size();
    std::vector<std::vector<double>> prob(n_scales);
    std::vector<double> fresh(n_scales, 0.0);
    for (std::size_t s = 0; s < n_scales; ++s) {
        prob[s] = softmax(returns[s], p.beta, allowed);
        double mean = 0.0, entropy = 0.0;
        std::size_t offered = 0;
        for (std::size_t d = 0; d < prob[s].size(); ++d) {
            if (!allowed[d]) continue;
            ++offered, mean += returns[s][d];
            if (prob[s][d] > 0) entropy -= prob[s][d] * std::log(prob[s][d]);
        }
        fresh[s] = offered ? mean / double(offered) / std::max(entropy, 1e-3) : 0.0;
    }
    if (scores.size() != n_scales) scores = fresh;
    else
        for (std::size_t s = 0; s < n_scales; ++s)
            scores[s] = (1 - p.scale_smoothing) * scores[s] + p.scale_smoothing * fresh[s];
    const auto weight = softmax(scores, p.scale_beta, std::vector<char>(n_scales, 1));
    std::vector<double> out(allowed.size(), 0.0);
    for (std::size_t s = 0; s < n_scales; ++s)
        for (std::size_t d = 0; d < out.size(); ++d) out[d] += weight[s] * prob[s][d];
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

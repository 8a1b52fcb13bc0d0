#include "bvc3d/navigation/authors_choice.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/vector_math.hpp"

namespace bvc3d {

namespace {

constexpr std::array<int, 3> turns{-1, 0, 1};  // the rollouts' turn options, in the authors' order

Vec2 unit_of(int d, int n_dir) {
    const double a = two_pi * d / n_dir;
    return {std::cos(a), std::sin(a)};
}

// The first option whose cumulative probability exceeds u; the last when rounding leaves u above them all.
int pick(const std::array<double, 3>& prob, double u) {
    double c = 0;
    for (int m = 0; m < 3; ++m)
        if (u < (c += prob[std::size_t(m)])) return m;
    return 2;
}

// A distinct rollout path: its last direction, its state (the copy's precision) and what it gave.
template <class S>
struct Node {
    int dir = 0;
    std::size_t parent = 0;
    std::vector<S> a;
    double r = 0;
    bool has_prob = false;
    std::array<double, 3> prob{};
    std::array<int, 3> child{-1, -1, -1};  // per turn option, once taken
};

template <class S>
TurningRollouts rollouts(const AdjacencyProduct& adj, std::span<const double> csum, std::span<const double> w,
                         std::span<const double> a0, std::span<const double> U, const AuthorsParams& p) {
    const auto n = std::size_t(adj.n_place());
    const int D = adj.n_dir();
    const auto K = std::size_t(p.samples), T = std::size_t(p.steps), Du = std::size_t(D);
    if (a0.size() != n || w.size() != n || csum.size() != Du * n)
        throw InputError("authors' rollouts: " + std::to_string(a0.size()) + " rates, " + std::to_string(w.size()) +
                         " weights and " + std::to_string(csum.size()) + " column sums for " + std::to_string(D) +
                         " directions of " + std::to_string(n) + " place cells");
    if (U.size() != (T - 1) * Du * K)
        throw InputError("authors' rollouts: " + std::to_string(U.size()) + " uniforms, not " +
                         std::to_string((T - 1) * Du * K));
    std::vector<Node<S>> nodes;
    std::vector<S> X(n * Du), Y(n * Du);
    std::vector<double> z(n);
    // The state after one step through W[dir] from `from` (what column `dir` of X held), with its read-out (in
    // double, before the state is kept in the copy's precision).
    const auto finish = [&](Node<S>& node, const std::vector<S>& from) {
        const auto k = std::size_t(node.dir);
        for (std::size_t j = 0; j < n; ++j) z[j] = std::max(double(Y[j * Du + k]) - double(from[j]), 0.0);
        vector_tanh(z.data(), z.data(), n);
        node.r = clamped_readout(w, z);
        node.a.assign(z.begin(), z.end());
    };
    // Step 0: every direction from a₀ at once.
    const std::vector<S> start(a0.begin(), a0.end());
    for (std::size_t j = 0; j < n; ++j) std::fill_n(&X[j * Du], Du, start[j]);
    adj.apply(std::span<const S>(X), std::span<S>(Y));
    for (int d = 0; d < D; ++d) {
        Node<S> node;
        node.dir = d;
        finish(node, start);
        nodes.push_back(std::move(node));
    }
    TurningRollouts out;
    out.products = Du;
    std::vector<std::size_t> at(Du * K);
    std::vector<double> G(Du * K);
    std::vector<Vec2> u(Du * K, Vec2::Zero());
    for (std::size_t t = 0; t < Du * K; ++t) {
        at[t] = t / K;
        G[t] = nodes[at[t]].r;
        u[t] = unit_of(nodes[at[t]].dir, D);
    }
    double g = 1.0;
    std::vector<char> which(Du);
    for (std::size_t k = 1; k < T; ++k) {
        g *= p.discount;
        // The turns: each path's options' probabilities once, each sample's draw.
        std::vector<std::size_t> pending;
        for (std::size_t t = 0; t < Du * K; ++t) {
            const std::size_t parent = at[t];
            if (!nodes[parent].has_prob) {
                Node<S>& node = nodes[parent];
                std::array<double, 3> logit{};
                for (std::size_t m = 0; m < 3; ++m) {
                    const int d = ((node.dir + turns[m]) % D + D) % D;
                    const double* c = &csum[std::size_t(d) * n];
                    double sum = 0;
                    for (std::size_t j = 0; j < n; ++j) sum += c[j] * double(node.a[j]);
                    logit[m] = sum / p.temperature;
                }
                const double top = *std::max_element(logit.begin(), logit.end());
                double total = 0;
                for (std::size_t m = 0; m < 3; ++m) total += node.prob[m] = std::exp(logit[m] - top);
                for (double& q : node.prob) q /= total;
                node.has_prob = true;
            }
            const int m = pick(nodes[parent].prob, U[((k - 1) * Du + t / K) * K + t % K]);
            if (nodes[parent].child[std::size_t(m)] < 0) {
                Node<S> child;
                child.dir = ((nodes[parent].dir + turns[std::size_t(m)]) % D + D) % D;
                child.parent = parent;
                nodes[parent].child[std::size_t(m)] = static_cast<int>(nodes.size());
                pending.push_back(nodes.size());
                nodes.push_back(std::move(child));
            }
            at[t] = std::size_t(nodes[parent].child[std::size_t(m)]);
        }
        // The new paths' states, as many directions at once as the pending paths allow.
        out.products += pending.size();
        while (!pending.empty()) {
            std::fill(which.begin(), which.end(), 0);
            std::vector<std::size_t> round, rest;
            for (std::size_t i : pending) {
                const auto d = std::size_t(nodes[i].dir);
                if (which[d]) {
                    rest.push_back(i);
                    continue;
                }
                which[d] = 1;
                round.push_back(i);
                const auto& from = nodes[nodes[i].parent].a;
                for (std::size_t j = 0; j < n; ++j) X[j * Du + d] = from[j];
            }
            adj.apply(std::span<const S>(X), std::span<S>(Y), which);
            for (std::size_t i : round) finish(nodes[i], nodes[nodes[i].parent].a);
            pending = std::move(rest);
        }
        for (std::size_t t = 0; t < Du * K; ++t) {
            G[t] += g * nodes[at[t]].r;
            u[t] += unit_of(nodes[at[t]].dir, D);
        }
    }
    out.R.assign(Du, 0.0), out.Var.assign(Du, 0.0), out.V.assign(Du, Vec2::Zero());
    for (std::size_t d = 0; d < Du; ++d) {
        double mean = 0;
        Vec2 v = Vec2::Zero();
        for (std::size_t j = 0; j < K; ++j) mean += G[d * K + j], v += u[d * K + j];
        mean /= double(K);
        double var = 0;
        for (std::size_t j = 0; j < K; ++j) var += (G[d * K + j] - mean) * (G[d * K + j] - mean);
        out.R[d] = mean, out.V[d] = v / double(K), out.Var[d] = var / double(K - 1);
    }
    return out;
}

}  // namespace

double clamped_readout(std::span<const double> w, std::span<const double> a) {
    double dot = 0, l1 = 0;
    for (std::size_t i = 0; i < a.size(); ++i) dot += w[i] * a[i], l1 += std::abs(a[i]);
    const double r = dot / std::max(l1, 1e-4);
    return std::isnan(r) ? 0.0 : std::clamp(r, 0.0, 1e6);
}

TurningRollouts turning_rollouts(const AdjacencyProduct& adj, std::span<const double> column_sums,
                                 std::span<const double> w_reward, std::span<const double> a0,
                                 std::span<const double> uniforms, const AuthorsParams& p) {
    return adj.precision() == StatePrecision::float32 ? rollouts<float>(adj, column_sums, w_reward, a0, uniforms, p)
                                                      : rollouts<double>(adj, column_sums, w_reward, a0, uniforms, p);
}

std::size_t rollout_uniforms(std::size_t scales, int n_dir, const AuthorsParams& p) {
    return scales * std::size_t(p.steps - 1) * std::size_t(n_dir) * std::size_t(p.samples);
}

ScaleMix mix_scales(std::span<const double> R, std::span<const double> Var, std::size_t dirs,
                    std::span<const double> reliability, std::span<const double> H_prev, const AuthorsParams& p) {
    ScaleMix m;
    m.dirs = dirs;
    m.scales = dirs ? R.size() / dirs : 0;
    const std::size_t S = m.scales;
    if (R.size() != S * dirs || Var.size() != R.size() || reliability.size() != S ||
        (!H_prev.empty() && H_prev.size() != S))
        throw InputError("mix_scales: returns, variances, reliabilities and entropies of different sizes");
    m.P_ds.assign(S * dirs, 0.0);
    m.M.assign(S, 0.0), m.H.assign(S, 0.0), m.H_smoothed.assign(S, 0.0);
    for (std::size_t s = 0; s < S; ++s) {
        const double* r = &R[s * dirs];
        const double top = *std::max_element(r, r + dirs);
        double sum = 0;
        for (std::size_t d = 0; d < dirs; ++d) sum += m.P_ds[s * dirs + d] = std::exp(p.beta * (r[d] - top));
        double entropy = 0, spread = 0;
        for (std::size_t d = 0; d < dirs; ++d) {
            double& q = m.P_ds[s * dirs + d];
            q /= std::max(sum, 1e-9);
            m.M[s] += q * r[d];
            entropy -= q * std::log(std::max(q, 1e-9));
            spread += q * Var[s * dirs + d];
        }
        m.H[s] = entropy + p.variance_weight * std::log1p(spread);
        m.H_smoothed[s] = H_prev.empty() ? m.H[s] : p.smoothing * m.H[s] + (1 - p.smoothing) * H_prev[s];
    }
    std::vector<double> inv(S);
    double inv_sum = 0;
    for (std::size_t s = 0; s < S; ++s) inv_sum += inv[s] = 1.0 / (m.H_smoothed[s] + 1e-9);
    m.iota.resize(S), m.q.resize(S), m.P_s.resize(S);
    double q_sum = 0;
    for (std::size_t s = 0; s < S; ++s) {
        m.iota[s] = inv[s] / std::max(inv_sum, 1e-9);
        q_sum += m.q[s] =
            m.M[s] * std::pow(m.iota[s], p.entropy_exponent) * std::pow(reliability[s], p.reliability_exponent);
    }
    for (double& q : m.q) q /= std::max(q_sum, 1e-9);
    const double top = S ? *std::max_element(m.q.begin(), m.q.end()) : 0.0;
    double w_sum = 0;
    for (std::size_t s = 0; s < S; ++s) w_sum += m.P_s[s] = std::exp(p.scale_beta * (m.q[s] - top));
    for (double& w : m.P_s) w /= std::max(w_sum, 1e-9);
    m.P.resize(S * dirs);
    for (std::size_t s = 0; s < S; ++s)
        for (std::size_t d = 0; d < dirs; ++d) m.P[s * dirs + d] = m.P_s[s] * m.P_ds[s * dirs + d];
    return m;
}

std::string to_string(HeadingRule r) {
    switch (r) {
        case HeadingRule::mix:
            return "mix";
        case HeadingRule::opposed:
            return "opposed";
        case HeadingRule::fallback:
            return "fallback";
    }
    return "?";
}

std::optional<HeadingChoice> heading_rule(std::span<const double> P, std::span<const double> R, std::span<const Vec2> V,
                                          std::span<const char> safe) {
    const std::size_t D = safe.size(), S = D ? P.size() / D : 0;
    if (P.size() != S * D || R.size() != P.size() || V.size() != P.size())
        throw InputError("heading_rule: P, R and V must each hold scales × directions values");
    std::vector<std::size_t> pairs;
    for (std::size_t s = 0; s < S; ++s)
        for (std::size_t d = 0; d < D; ++d)
            if (safe[d]) pairs.push_back(s * D + d);
    if (pairs.empty()) return std::nullopt;
    HeadingChoice h;
    double total = 0;
    for (std::size_t i : pairs) total += P[i];
    h.P_prime.assign(S * D, 0.0);
    for (std::size_t i : pairs) {
        h.P_prime[i] = P[i] / std::max(total, 1e-9);
        h.c += h.P_prime[i] * V[i];
    }
    // The best pair by R (the first on ties) and the best of the rest.
    const auto best_of = [&](std::size_t skip) {
        std::size_t best = skip;
        for (std::size_t i : pairs)
            if (i != skip && (best == skip || R[i] > R[best])) best = i;
        return best;
    };
    const std::size_t none = std::numeric_limits<std::size_t>::max();
    const std::size_t i1 = best_of(none);
    if (pairs.size() >= 2) {
        const std::size_t i2 = best_of(i1);
        const double n1 = V[i1].norm(), n2 = V[i2].norm();
        if (n1 > 1e-9 && n2 > 1e-9 && V[i1].dot(V[i2]) / (n1 * n2) < -0.75) h.c = V[i1], h.rule = HeadingRule::opposed;
    }
    if (h.c.norm() < 1e-6) h.c = V[i1], h.rule = HeadingRule::fallback;
    h.heading = std::atan2(h.c.y(), h.c.x());
    if (h.heading < 0) h.heading += two_pi;
    h.scale_weights.assign(S, 0.0);
    for (std::size_t s = 0; s < S; ++s)
        for (std::size_t d = 0; d < D; ++d) h.scale_weights[s] += h.P_prime[s * D + d];
    return h;
}

std::vector<double> sector_minima(std::span<const double> ranges, std::span<const double> azimuths, int n_dir,
                                  SafetySector sector) {
    if (ranges.size() != azimuths.size()) throw InputError("sector_minima: as many ranges as azimuths");
    const double width = two_pi / n_dir, shift = sector == SafetySector::centred ? width / 2 : 0.0;
    std::vector<double> out(std::size_t(n_dir), std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < ranges.size(); ++i) {
        double a = std::fmod(azimuths[i] + shift, two_pi);
        if (a < 0) a += two_pi;
        const auto d = std::size_t(static_cast<int>(std::floor(a / width)) % n_dir);
        out[d] = std::min(out[d], ranges[i]);
    }
    return out;
}

AuthorsReliability::AuthorsReliability(std::size_t scales, const AuthorsParams& p)
    : p_(p), rho_(scales, 1.0), contributions_(scales, 0.0), cooldown_(scales, 0) {}

double AuthorsReliability::clamp(double x) const { return std::clamp(x, p_.reliability_floor, 1.0); }

namespace {
double wrap_deg(double x) {
    const double m = std::fmod(x + 180.0, 360.0);
    return (m < 0 ? m + 360.0 : m) - 180.0;
}
}  // namespace

AuthorsReliability::Phase AuthorsReliability::begin(double heading_deg) {
    for (int& c : cooldown_) c = std::max(c - 1, 0);
    const bool low = std::all_of(rho_.begin(), rho_.end(), [&](double r) { return r < p_.explore_trigger; });
    if (low && !triggered_) force_explore_ = p_.explore_blocks, triggered_ = true;
    else if (!low) triggered_ = false;
    if (force_explore_ > 0) {
        --force_explore_;
        for (double& r : rho_) r = clamp(r * p_.good_factor);
        return Phase::explore;
    }
    if (!last_heading_) last_heading_ = heading_deg;
    const double diff = std::abs(wrap_deg(heading_deg - *last_heading_));
    accumulated_ += diff;
    last_heading_ = heading_deg;
    if (!last_weights_.empty())
        for (std::size_t s = 0; s < rho_.size(); ++s) contributions_[s] += last_weights_[s] * diff / 360.0;
    if (accumulated_ >= 360.0) {
        ++loops_, ++full_turns_;
        accumulated_ -= 360.0;
        if (since_loop_ > p_.max_decisions_between_loops) loops_ = 1;
        since_loop_ = 0;
        double total = 0;
        for (double c : contributions_) total += c;
        if (loops_ >= 1 && total > 0) {
            for (std::size_t s = 0; s < rho_.size(); ++s) {
                rho_[s] = clamp(rho_[s] * (1.0 - contributions_[s] * p_.loop_penalty));
                if (contributions_[s] > 0) cooldown_[s] = p_.cooldown;
                contributions_[s] = 0.0;
            }
            ++penalties_;
        }
        if (loops_ >= p_.loop_reset) loops_ = 0, accumulated_ = 0, since_loop_ = 0;
    } else {
        ++since_loop_;
        if (since_loop_ > p_.max_decisions_between_loops) loops_ = 0;
    }
    return Phase::decide;
}

void AuthorsReliability::movement_headings(std::span<const double> headings_deg) {
    for (double h : headings_deg) {
        if (last_heading_) accumulated_ += std::abs(wrap_deg(h - *last_heading_));
        last_heading_ = h;
    }
}

void AuthorsReliability::end(std::span<const double> scale_weights, bool contact) {
    last_weights_.assign(scale_weights.begin(), scale_weights.end());
    const auto k = std::size_t(std::max_element(last_weights_.begin(), last_weights_.end()) - last_weights_.begin());
    if (contact) {
        if (force_explore_ == 0) rho_[k] = clamp(rho_[k] * p_.bad_factor), cooldown_[k] = p_.cooldown;
    } else if (cooldown_[k] <= 0) {
        rho_[k] = std::min(rho_[k] * p_.good_factor, 1.0);
    }
}

AuthorsDecision authors_decide(std::span<const DecisionScale> scales, std::span<const double> uniforms,
                               std::span<const double> sector_min, std::span<const double> reliability,
                               std::span<const double> H_prev, const AuthorsParams& p) {
    AuthorsDecision out;
    if (scales.empty()) throw InputError("authors_decide: no scales");
    const int D = scales.front().adjacency->n_dir();
    const std::size_t per_scale = rollout_uniforms(1, D, p);
    if (uniforms.size() != per_scale * scales.size())
        throw InputError("authors_decide: " + std::to_string(uniforms.size()) + " uniforms, not " +
                         std::to_string(per_scale * scales.size()));
    if (sector_min.size() != std::size_t(D)) throw InputError("authors_decide: a least range per direction");
    std::vector<double> R, Var;
    std::vector<Vec2> V;
    for (std::size_t s = 0; s < scales.size(); ++s) {
        const DecisionScale& sc = scales[s];
        if (sc.adjacency->n_dir() != D) throw InputError("authors_decide: scales with different directions");
        out.rollouts.push_back(turning_rollouts(*sc.adjacency, sc.column_sums, sc.w_reward, sc.rates,
                                                uniforms.subspan(s * per_scale, per_scale), p));
        const auto& r = out.rollouts.back();
        R.insert(R.end(), r.R.begin(), r.R.end());
        Var.insert(Var.end(), r.Var.begin(), r.Var.end());
        V.insert(V.end(), r.V.begin(), r.V.end());
    }
    out.mix = mix_scales(R, Var, std::size_t(D), reliability, H_prev, p);
    std::vector<char> safe(sector_min.size());
    for (std::size_t d = 0; d < safe.size(); ++d) safe[d] = sector_min[d] >= p.safe_distance;
    out.choice = heading_rule(out.mix.P, R, V, safe);
    return out;
}

}  // namespace bvc3d

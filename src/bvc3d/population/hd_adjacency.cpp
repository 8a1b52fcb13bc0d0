#include "bvc3d/population/hd_adjacency.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/memory.hpp"

namespace bvc3d {

const params::Table<AdjacencyParams>& AdjacencyParams::table() {
    using namespace params;
    static const Table<AdjacencyParams> t(
        "adjacency",
        {integer("n_hd", &AdjacencyParams::n_hd, closed(1, 64), "HD cells, one transition matrix each"),
         real("eta", &AdjacencyParams::eta, closed(0, 1e6), "η of the traces"),
         real("tau_x", &AdjacencyParams::tau_x, above(0), "place-cell trace: x += (η/τ_x)(v − x)"),
         real("tau_hd", &AdjacencyParams::tau_hd, above(0), "HD trace: Υ += (η/τ_hd)(v_hd − Υ)"),
         real("rate", &AdjacencyParams::rate, finite(), "a in ΔW_rec[k] = a·Υ_k·(v xᵀ − x vᵀ)"),
         real("decay", &AdjacencyParams::decay, closed_open(0, 1), "every weight × (1 − decay) per learning step"),
         real("prune", &AdjacencyParams::prune, closed_open(0, 1),
              "navigation's products leave out |w| <= prune × the matrix's largest; 0: exact"),
         choice("rollout_weights", &AdjacencyParams::rollout_weights,
                {{RolloutWeights::float32, "float32"}, {RolloutWeights::float16, "float16"}},
                "navigation's rollouts read the kept weights as float32 matrices, or as 16-bit floats on one pattern "
                "for all directions (faster, each weight within 2^-11 of itself)")
             .quiet_at_default()});
    return t;
}

std::vector<double> hd_rates(double heading, int n) {
    std::vector<double> v(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) v[static_cast<std::size_t>(k)] = std::cos(heading - 2 * pi * k / n);
    return v;
}

HdAdjacency::HdAdjacency(int n_place, const AdjacencyParams& params) : n_(n_place), p_(params) {
    p_.validate();
    if (n_place < 1) throw InputError("adjacency: needs at least one place cell");
    check_memory(
        bytes(n_place, p_.n_hd),
        "the adjacency (" + std::to_string(p_.n_hd) + " matrices of " + std::to_string(n_place) + "² place cells)",
        "use fewer place cells or HD cells");
    m_.assign(std::size_t(p_.n_hd) * n_ * n_, 0.0f);
    x_.assign(std::size_t(n_), 0.0);
    u_.assign(std::size_t(p_.n_hd), 0.0);
}

void HdAdjacency::learn(std::span<const double> place, std::span<const double> hd, bool bumped) {
    if (place.size() != x_.size() || hd.size() != u_.size())
        throw InputError("adjacency: expects " + std::to_string(n_) + " place and " + std::to_string(p_.n_hd) +
                         " HD rates, got " + std::to_string(place.size()) + " and " + std::to_string(hd.size()));
    const double gx = p_.eta / p_.tau_x, gu = p_.eta / p_.tau_hd;
    for (std::size_t i = 0; i < x_.size(); ++i) x_[i] += gx * (place[i] - x_[i]);
    for (std::size_t k = 0; k < u_.size(); ++k) u_[k] += gu * (hd[k] - u_[k]);
    if (!bumped) {
        active_.clear();
        for (int i = 0; i < n_; ++i)
            if (place[std::size_t(i)] != 0.0) active_.push_back(i);
        for (int k = 0; k < p_.n_hd; ++k) {
            const double c = p_.rate * u_[std::size_t(k)] / scale_;
            if (c == 0.0) continue;
            // v xᵀ: the active rows gain c·v_i·x; x vᵀ: the active columns lose c·v_j·x.
            for (int i : active_) {
                float* row = &m_[index(k, i, 0)];
                const double cv = c * place[std::size_t(i)];
                for (int j = 0; j < n_; ++j) row[j] += static_cast<float>(cv * x_[std::size_t(j)]);
            }
            for (int j : active_) {
                const double cv = c * place[std::size_t(j)];
                for (int i = 0; i < n_; ++i) m_[index(k, i, j)] -= static_cast<float>(cv * x_[std::size_t(i)]);
            }
        }
    }
    scale_ *= 1.0 - p_.decay;
    if (scale_ < 1e-6) {
        for (float& w : m_) w = static_cast<float>(w * scale_);
        scale_ = 1.0;
    }
}

void HdAdjacency::set_weights(std::span<const float> w) {
    if (w.size() != m_.size())
        throw InputError("adjacency: expects " + std::to_string(m_.size()) + " weights, got " +
                         std::to_string(w.size()));
    m_.assign(w.begin(), w.end());
    scale_ = 1.0;
    antisymmetric_ = true;
    for (int k = 0; k < p_.n_hd && antisymmetric_; ++k)
        for (int i = 0; i < n_ && antisymmetric_; ++i)
            for (int j = 0; j <= i; ++j)
                if (m_[index(k, i, j)] != -m_[index(k, j, i)]) {
                    antisymmetric_ = false;
                    break;
                }
}

void HdAdjacency::apply(int k, std::span<const double> x, std::span<double> out) const {
    // Few active cells (a rollout's state, replay's first steps): W·x = −Σ_j x_j·W[j, :] for an antisymmetric W,
    // rows read in order, O(active · n) instead of O(n²).
    std::size_t active = 0;
    for (double v : x) active += v != 0.0;
    if (antisymmetric_ && 4 * active < std::size_t(n_)) {
        std::fill(out.begin(), out.end(), 0.0);
        for (int j = 0; j < n_; ++j) {
            const double xj = x[std::size_t(j)];
            if (xj == 0.0) continue;
            const float* row = &m_[index(k, j, 0)];
            for (int i = 0; i < n_; ++i) out[std::size_t(i)] -= xj * double(row[i]);
        }
        for (double& o : out) o *= scale_;
        return;
    }
    for (int i = 0; i < n_; ++i) {
        const float* row = &m_[index(k, i, 0)];
        double sum = 0.0;
        for (int j = 0; j < n_; ++j) sum += double(row[j]) * x[std::size_t(j)];
        out[std::size_t(i)] = scale_ * sum;
    }
}

HdAdjacency::Kept HdAdjacency::kept(double prune, const char* copy) const {
    if (!(prune >= 0 && prune < 1)) throw InputError("adjacency: prune must lie in [0, 1)");
    if (std::size_t(n_) > std::size_t(UINT16_MAX) + 1 || std::size_t(n_) * std::size_t(n_) > UINT32_MAX)
        throw InputError(std::string("adjacency: too many place cells for the ") + copy + " copy (" +
                         std::to_string(n_) + "; at most 65 536)");
    Kept out{std::vector<float>(std::size_t(p_.n_hd), 0.0f), {}};
    for (int k = 0; k < p_.n_hd; ++k) {
        const float* m = &m_[index(k, 0, 0)];
        float& top = out.top[std::size_t(k)];
        for (std::size_t e = 0; e < std::size_t(n_) * std::size_t(n_); ++e) top = std::max(top, std::abs(m[e]));
        // |w| > cut: with prune = 0, every non-zero weight (symmetric in i, j: the copy stays antisymmetric).
        out.cut.push_back(static_cast<float>(prune * double(top)));
    }
    return out;
}

std::vector<StateArray> HdAdjacency::state() const {
    const auto n = std::size_t(n_), h = std::size_t(p_.n_hd);
    return {{"adjacency", {h, n, n}, m_},
            {"adjacency_scale", {1}, std::vector<double>{scale_}},
            {"place_trace", {n}, x_},
            {"hd_trace", {h}, u_}};
}

void HdAdjacency::restore(const std::vector<StateArray>& state) {
    m_ = state_floats(state, "adjacency", m_.size());
    scale_ = state_doubles(state, "adjacency_scale", 1)[0];
    x_ = state_doubles(state, "place_trace", x_.size());
    u_ = state_doubles(state, "hd_trace", u_.size());
}

AdjacencyPopulation::AdjacencyPopulation(int n_place, const AdjacencyParams& params) : adj_(n_place, params) {}

void AdjacencyPopulation::step(const StepBlock& block, std::span<const std::span<const double>> inputs,
                               std::span<double>) {
    const auto n = std::size_t(adj_.n_place()), h = std::size_t(adj_.n_hd());
    for (std::size_t s = 0; s < block.size(); ++s) {
        if (!block.learn[s]) continue;
        adj_.learn(inputs[0].subspan(s * n, n), inputs[1].subspan(s * h, h), block.steps[s].bumped);
    }
}

}  // namespace bvc3d

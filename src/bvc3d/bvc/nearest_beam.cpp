#include "bvc3d/bvc/nearest_beam.hpp"

#include <algorithm>
#include <cmath>

#include "bvc3d/bvc/bvc_kernels.hpp"
#include "bvc3d/bvc/return_check.hpp"
#include "bvc3d/bvc/truncation_bound.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/vector_math.hpp"

namespace bvc3d {

NearestBeamReading::NearestBeamReading(const LayerTuning& tuning)
    : t_(tuning), window_r_(tuning.distance.window(pruning::tiny_r)) {
    // θ_k, padded with NaN to whole vectors of 8 (kernels::nearest_returns).
    const std::size_t dirs8 = (static_cast<std::size_t>(t_.n_dir) + 7) / 8 * 8;
    dir_angle_.assign(dirs8, NAN);
    for (int k = 0; k < t_.n_dir; ++k) dir_angle_[k] = k * two_pi / t_.n_dir;
    best_return_.assign(dirs8, 0);
    best_gap_.assign(dirs8, 0.0);
}

bool NearestBeamReading::raw(std::span<const LidarReturn> returns, std::span<double> out, bool prune) {
    // For each direction, the first return with the smallest |wrap(azimuth - θ_k)|.
    const int K = t_.n_dir, M = t_.n_per_axis;
    near_azimuth_.clear();
    near_index_.clear();
    for (std::size_t j = 0; j < returns.size(); ++j) {
        if (is_no_return(returns[j])) continue;
        check_return(returns[j], j);
        near_azimuth_.push_back(wrap_pi(returns[j].azimuth));
        near_index_.push_back(j);
    }
    kernels::nearest_returns(near_azimuth_.data(), near_azimuth_.size(), dir_angle_.data(), K, best_return_.data(),
                             best_gap_.data());
    for (int k = 0; k < K; ++k) {  // back to the returns' own indices
        const auto i = static_cast<std::size_t>(best_return_[k]);
        best_return_[k] = static_cast<std::int64_t>(i < near_index_.size() ? near_index_[i] : returns.size());
    }
    // Pruned, a direction's profile is evaluated over its distance window only: a cell outside it would get less
    // than tiny_r of D's peak. Those Gaussian tails (down to 1e-56 of the peak) were the subnormal float rates, and
    // the weights Oja's rule grew from them, that made the place cells take a microcode assist per product on many
    // CPUs.
    const double dd = t_.spacing, inv_dd = dd > 0 ? 1.0 / dd : 0.0, sigma = t_.distance.sigma;
    prune = prune && dd > 0;
    // The exponents of D(r − d_m) for every cell to evaluate, then one batched exp.
    cells_.clear();
    exponents_.clear();
    for (int k = 0; k < K; ++k) {
        if (static_cast<std::size_t>(best_return_[k]) == returns.size()) continue;
        const double r = returns[static_cast<std::size_t>(best_return_[k])].range;
        int m_lo = 0, m_hi = M - 1;
        if (prune) {  // a superset of |r - d_m| <= window
            const double lo = (r - window_r_) * inv_dd, hi = (r + window_r_) * inv_dd;
            m_lo = lo > 0 ? static_cast<int>(std::min(lo, 1e9)) : 0;
            m_hi = std::min(static_cast<int>(std::min(hi, static_cast<double>(M - 2))) + 1, M - 1);
        }
        for (int m = m_lo; m <= m_hi; ++m) {
            const double x = r - m * dd;
            cells_.push_back(static_cast<std::size_t>(k) * M + m);
            exponents_.push_back(-0.5 * x * x / (sigma * sigma));
        }
    }
    vector_exp(exponents_.data(), exponents_.data(), exponents_.size());
    double max_raw = 0;
    for (std::size_t i = 0; i < cells_.size(); ++i) {
        const double v = t_.distance.peak * exponents_[i];
        out[cells_[i]] = v;
        max_raw = std::max(max_raw, v);
    }
    return !prune || t_.distance.peak * pruning::tiny_r <= pruning::tolerance * max_raw;
}

}  // namespace bvc3d

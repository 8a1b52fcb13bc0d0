#include "bvc3d/navigation/scale_mix.hpp"

#include <cmath>
#include <limits>

namespace bvc3d {

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

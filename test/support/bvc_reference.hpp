#pragma once
// The BVC equations of docs/model-reference.md#boundary-vector-cells written out literally (plain loops over every
// return and every cell, no pruning, no shared code with the library), as the oracle for tests and the dense baseline
// for benchmarks.
#include <cmath>
#include <vector>

#include "bvc3d/bvc/boundary_vector_layer.hpp"

namespace bvc3d::reference {

inline double gauss(double x, double sigma) {
    return std::exp(-x * x / (2 * sigma * sigma)) / std::sqrt(2 * M_PI * sigma * sigma);
}

// wrap() into (-pi, pi] through atan2, independently of the library's wrap_pi.
inline double wrap(double a) {
    double w = std::atan2(std::sin(a), std::cos(a));
    return w == -M_PI ? M_PI : w;
}

inline std::vector<double> bvc_raw(const BvcParams& p, const std::vector<LidarReturn>& returns) {
    const int L = p.elevations.empty() ? 1 : static_cast<int>(p.elevations.size());
    const int K = p.n_dir, M = p.n_per_axis;
    std::vector<double> raw(static_cast<std::size_t>(L) * K * M, 0.0);
    for (int l = 0; l < L; ++l)
        for (int k = 0; k < K; ++k)
            for (int m = 0; m < M; ++m) {
                const double theta_k = k * 2 * M_PI / K;
                const double d_m = M > 1 ? m * p.max_dist / (M - 1) : 0.0;
                double sum = 0;
                if (p.reading == BvcReading::nearest_beam) {
                    // The single return whose azimuth is closest to theta_k (first on ties).
                    int best = -1;
                    double gap = 1e300;
                    for (std::size_t j = 0; j < returns.size(); ++j) {
                        if (!std::isfinite(returns[j].range)) continue;
                        const double g = std::abs(wrap(returns[j].azimuth - theta_k));
                        if (g < gap) gap = g, best = static_cast<int>(j);
                    }
                    if (best >= 0) sum = gauss(returns[best].range - d_m, p.sigma_r);
                } else {
                    for (const auto& r : returns) {
                        if (!std::isfinite(r.range)) continue;
                        double term = gauss(r.range - d_m, p.sigma_r) * gauss(wrap(r.azimuth - theta_k), p.sigma_theta);
                        if (!p.elevations.empty()) term *= gauss(r.elevation - p.elevations[l], p.sigma_phi);
                        sum += term;
                    }
                }
                raw[(static_cast<std::size_t>(l) * K + k) * M + m] = sum;
            }
    return raw;
}

inline std::vector<double> bvc_rates(const BvcParams& p, const std::vector<LidarReturn>& returns) {
    auto raw = bvc_raw(p, returns);
    double mx = 0;
    for (double v : raw) mx = std::max(mx, v);
    for (double& v : raw) v = mx > 0 ? v / (2 * mx) : 0.0;
    return raw;
}

}  // namespace bvc3d::reference

#pragma once
// The Kolmogorov-Smirnov test of a sample against a continuous CDF, for the walks' turn
// distributions: the statistic, its 1 % critical value (large-sample), and the normal CDF.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace bvc3d::reference {

inline double normal_cdf(double x, double sd) { return 0.5 * std::erfc(-x / (sd * std::sqrt(2.0))); }

// sup |F_n - F| over the sample.
template <class Cdf>
double ks_statistic(std::vector<double> xs, Cdf cdf) {
    std::sort(xs.begin(), xs.end());
    const double n = static_cast<double>(xs.size());
    double d = 0;
    for (std::size_t i = 0; i < xs.size(); ++i) {
        const double f = cdf(xs[i]);
        d = std::max({d, (i + 1) / n - f, f - i / n});
    }
    return d;
}

inline double ks_critical_1pct(std::size_t n) { return 1.628 / std::sqrt(static_cast<double>(n)); }

}  // namespace bvc3d::reference

// The batched exp of the hot loops (core/vector_exp.hpp) against long double expl: within 1 ulp of the
// exact value, for every count of arguments (whole vectors and tails), in place, and at the edges.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "bvc3d/core/vector_exp.hpp"

using namespace bvc3d;

namespace {
// |y - exp(x)| in units of the last place of double at exp(x), exp(x) from 64-bit-mantissa expl.
double ulps_from_exact(double x, double y) {
    const long double exact = std::exp(static_cast<long double>(x));
    const double rounded = static_cast<double>(exact);
    if (rounded == 0.0 || std::isinf(rounded)) return y == rounded ? 0.0 : INFINITY;
    const double ulp = std::nextafter(rounded, INFINITY) - rounded;
    return static_cast<double>(std::abs(static_cast<long double>(y) - exact) / ulp);
}
}  // namespace

TEST(VectorExp, WithinOneUlpOfTheExactValue) {
    std::mt19937_64 gen(7);
    // The BVC layer's arguments: -h·x0² down to about -400 and 2h·x0·Δ up to about 620; the rest of
    // the finite range too.
    std::uniform_real_distribution<double> wide(-745.0, 709.0), narrow(-20.0, 5.0);
    std::vector<double> x(100000), y(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = i % 2 ? wide(gen) : narrow(gen);
    vector_exp(x.data(), y.data(), x.size());
    double worst = 0;
    std::size_t differ_from_libm = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        worst = std::max(worst, ulps_from_exact(x[i], y[i]));
        differ_from_libm += y[i] != std::exp(x[i]);
    }
    EXPECT_LE(worst, 1.0);
    EXPECT_LT(differ_from_libm, x.size() / 5);  // both are faithful: they disagree on a minority only
}

TEST(VectorExp, TailsInPlaceAndEdges) {
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<double> edges{0.0, -0.0, 1.0, -1.0, 709.7, 710.0, -708.0, -745.2, -800.0, 1e-300, -inf, inf};
    for (std::size_t n = 0; n <= edges.size(); ++n) {  // every tail length of every vector width
        std::vector<double> y(edges.begin(), edges.begin() + static_cast<std::ptrdiff_t>(n));
        vector_exp(y.data(), y.data(), n);  // in place
        for (std::size_t i = 0; i < n; ++i) {
            if (std::isinf(edges[i])) {
                EXPECT_EQ(y[i], edges[i] > 0 ? inf : 0.0) << edges[i];
            } else {
                EXPECT_LE(ulps_from_exact(edges[i], y[i]), 1.0) << edges[i];
            }
        }
    }
    double nan = std::numeric_limits<double>::quiet_NaN(), out = 0;
    vector_exp(&nan, &out, 1);
    EXPECT_TRUE(std::isnan(out));
}

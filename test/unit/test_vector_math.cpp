// The batched exp of the hot loops (core/vector_math.hpp) against long double expl: within 1 ulp of the
// exact value, for every count of arguments (whole vectors and tails), in place, and at the edges.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "bvc3d/core/vector_math.hpp"

using namespace bvc3d;

namespace {
// |y - f(x)| in units of the last place of double at f(x), f(x) from 64-bit-mantissa long double (exp by default).
double ulps_from_exact(double x, double y, long double (*f)(long double) = expl) {
    const long double exact = f(static_cast<long double>(x));
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

TEST(VectorTanh, WithinThreeAndAHalfUlpOfTheExactValue) {
    std::mt19937_64 gen(11);
    // The rollouts' arguments: [W·x − x]+, from 0 up to a few; and the rest of the range, tiny and large, both signs.
    std::uniform_real_distribution<double> rollout(0.0, 4.0), wide(-25.0, 25.0), tiny(-30.0, 0.0);
    std::vector<double> x(100000), y(x.size());
    for (std::size_t i = 0; i < x.size(); ++i)
        x[i] = i % 3 == 0 ? rollout(gen) : i % 3 == 1 ? wide(gen) : std::ldexp(1.0, int(tiny(gen))) * (i % 2 ? 1 : -1);
    vector_tanh(x.data(), y.data(), x.size());
    double worst = 0;
    for (std::size_t i = 0; i < x.size(); ++i) worst = std::max(worst, ulps_from_exact(x[i], y[i], tanhl));
    EXPECT_LE(worst, 3.5);
}

TEST(VectorTanh, TailsInPlaceAndEdges) {
    const double inf = std::numeric_limits<double>::infinity();
    const std::vector<double> edges{0.0, -0.0, 1e-300, 1e-9, 0.5, -0.5, 1.0, 19.0, 25.0, -40.0, inf, -inf};
    for (std::size_t n = 0; n <= edges.size(); ++n) {  // every tail length of every vector width
        std::vector<double> y(edges.begin(), edges.begin() + static_cast<std::ptrdiff_t>(n));
        vector_tanh(y.data(), y.data(), n);  // in place
        for (std::size_t i = 0; i < n; ++i) {
            if (std::isinf(edges[i])) {
                EXPECT_EQ(y[i], edges[i] > 0 ? 1.0 : -1.0) << edges[i];
            } else {
                EXPECT_LE(ulps_from_exact(edges[i], y[i], tanhl), 3.5) << edges[i];
            }
            if (edges[i] == 0.0) {
                EXPECT_EQ(std::signbit(y[i]), std::signbit(edges[i]));  // tanh(±0) = ±0
            }
        }
    }
    double nan = std::numeric_limits<double>::quiet_NaN(), out = 0;
    vector_tanh(&nan, &out, 1);
    EXPECT_TRUE(std::isnan(out));
}

#pragma once
// Angle helpers shared by every stage (docs/model-reference.md#conventions: radians inside the code).
#include <cmath>
#include <numbers>

namespace bvc3d {

inline constexpr double pi = std::numbers::pi;
inline constexpr double two_pi = 2.0 * std::numbers::pi;

// Wrap an angle into (-pi, pi].
inline double wrap_pi(double a) {
    if (a > -pi && a <= pi) return a;
    // One turn out (a sum of two wrapped angles): a ∓ 2π is exact (Sterbenz's lemma) and is what the
    // remainder below gives, without a libm call (but for -2π, whose remainder is -0).
    if (a > pi && a < 3 * pi) return a - two_pi;
    if (a <= -pi && a > -3 * pi && a != -two_pi) return a + two_pi;
    double w = std::remainder(a, two_pi);  // in [-pi, pi]
    return w <= -pi ? w + two_pi : w;
}

inline double deg_to_rad(double d) { return d * (pi / 180.0); }
inline double rad_to_deg(double r) { return r * (180.0 / pi); }

}  // namespace bvc3d

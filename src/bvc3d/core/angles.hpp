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
    double w = std::remainder(a, two_pi);  // in [-pi, pi]
    return w <= -pi ? w + two_pi : w;
}

inline double deg_to_rad(double d) { return d * (pi / 180.0); }
inline double rad_to_deg(double r) { return r * (180.0 / pi); }

}  // namespace bvc3d

#pragma once
// BVC stage: what a layer accepts as a return. Takes: one LiDAR return. Gives: whether it is "no return" (a NaN or
// +inf range, skipped) and an InputError naming a return that is neither absent nor valid.
#include <cmath>
#include <cstddef>
#include <string>

#include "bvc3d/core/error.hpp"
#include "bvc3d/sensor/lidar.hpp"

namespace bvc3d {

// NaN or +inf range: the conventional "no return" marker; the return is skipped.
inline bool is_no_return(const LidarReturn& r) { return std::isnan(r.range) || r.range == INFINITY; }

// A negative range, -inf, or a non-finite angle: InputError naming the return.
inline void check_return(const LidarReturn& r, std::size_t index) {
    auto bad = [&](const std::string& what) {
        throw InputError("LiDAR return " + std::to_string(index) + ": " + what);
    };
    if (r.range < 0) bad("negative range " + std::to_string(r.range));
    if (!std::isfinite(r.azimuth)) bad("azimuth is not finite");
    if (!std::isfinite(r.elevation)) bad("elevation is not finite");
}

}  // namespace bvc3d

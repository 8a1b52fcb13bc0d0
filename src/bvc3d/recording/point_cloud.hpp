#pragma once
// A scan as the recording readers give it and the writers take it: N points, x y z in metres in
// the sensor's frame. Readers drop points with a NaN or infinite coordinate (a real LiDAR's
// "no return") and say how many they dropped.
#include <cstddef>
#include <vector>

namespace bvc3d::recording {

struct PointCloud {
    std::vector<double> xyz;            // N×3 row-major: x0 y0 z0 x1 y1 z1 ...
    std::size_t dropped_nonfinite = 0;  // points the reader dropped for a NaN/inf coordinate

    std::size_t size() const { return xyz.size() / 3; }
};

}  // namespace bvc3d::recording

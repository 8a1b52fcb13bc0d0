#pragma once
// One unit of the BVC layer's work between its bookkeeping and its vector kernel (bvc_kernels.hpp,
// private): public only because the layer keeps a buffer of them.
#include <cstdint>

namespace bvc3d::kernels {

// One return's distance profile c_r·exp(-(r - (m + n)·Δ)²/2σ²), n < W (its window, from the block of 8
// cells m starts), evaluated as a·b^n·decay[n] (a = c_r·exp(-h x0²), b = exp(2h x0 Δ), x0 = r - m·Δ,
// decay[n] = exp(-h n²Δ²)), to be added with a weight to each of `rows` rows; the rows' offsets (into
// the sums, at m) and weights follow one another in the arrays passed to add_distance_profiles.
struct ProfileJob {
    double a, b;
    std::int32_t width, rows;
};

}  // namespace bvc3d::kernels

#pragma once
// One unit of the BVC layer's work between its bookkeeping and its vector kernel (bvc_kernels.hpp,
// private): public only because the layer keeps a buffer of them.
#include <cstdint>

namespace bvc3d::kernels {

// One return's distance profile s·c_r·exp(-(r - (m + n)·Δ)²/2σ²), n < width (its window, from the block
// of 8 cells m), evaluated as a·b^n·decay[n] (a = s·c_r·exp(-h x0²), b = exp(2h x0 Δ), x0 = r - m·Δ,
// decay[n] = exp(-h n²Δ²)), to be added with weight A_d to the row of each direction d its angular
// record lists: sums[base + dir_d·stride + n]. The record (the BVC layer's memo) is a count and that
// many directions in one array, a key and the factors A_d in another, both at `record`.
struct ProfileJob {
    double a, b;         // until the layer computes them: x0, and the scale s
    std::uint32_t base;  // the cell m of direction 0, in the sums
    std::uint32_t record;
    std::int32_t width, unused;
};

}  // namespace bvc3d::kernels

#include "bvc3d/bvc/bvc_kernels.hpp"

#include "bvc3d/core/simd.hpp"

namespace bvc3d::kernels {

BVC3D_DISPATCH
void add_distance_profile(double a, double b, const double* __restrict decay, int W, const double* w,
                          double* const* rows, int count, double* __restrict scratch) {
    // Eight independent power chains b^(n+t), t = 0..7, stepped by b^8.
    double pw[8];
    pw[0] = 1.0;
    for (int t = 1; t < 8; ++t) pw[t] = pw[t - 1] * b;
    const double b8 = pw[7] * b;
    const int padded = (W + 7) & ~7;
    for (int n = 0; n < padded; n += 8)
        for (int t = 0; t < 8; ++t) {
            scratch[n + t] = a * pw[t] * decay[n + t];
            pw[t] *= b8;
        }
    for (int i = 0; i < count; ++i) {
        double* __restrict row = rows[i];
        const double wi = w[i];
        for (int n = 0; n < W; ++n) row[n] += wi * scratch[n];
    }
}

}  // namespace bvc3d::kernels

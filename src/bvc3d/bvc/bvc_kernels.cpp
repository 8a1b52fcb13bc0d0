#include "bvc3d/bvc/bvc_kernels.hpp"

#include "bvc3d/core/simd.hpp"

namespace bvc3d::kernels {

using simd::d8;

BVC3D_DISPATCH
void add_distance_profile(double a, double b, const double* decay, int W, const double* w, double* const* rows,
                          int count, double* scratch) {
    // Eight independent power chains b^(n+t), t = 0..7, stepped by b^8; the first powers come
    // from a product tree (three multiplications deep rather than eight).
    const double b2 = b * b, b4 = b2 * b2;
    const d8 pw0 = {1.0, b, b2, b2 * b, b4, b4 * b, b4 * b2, b4 * (b2 * b)};
    d8 pw = pw0;
    const double b8 = b4 * b4;
    const int padded = (W + 7) & ~7;
    for (int n = 0; n < padded; n += 8) {
        d8 dec;
        simd::load(dec, decay + n);
        const d8 u = a * pw * dec;
        simd::store(scratch + n, u);
        pw *= b8;
    }
    for (int n = W; n < padded; ++n) scratch[n] = 0.0;  // the padding only ever receives exact zeros
    for (int i = 0; i < count; ++i) {
        double* row = rows[i];
        const double wi = w[i];
        for (int n = 0; n < padded; n += 8) {
            d8 r, u;
            simd::load(r, row + n);
            simd::load(u, scratch + n);
            r += wi * u;
            simd::store(row + n, r);
        }
    }
}

}  // namespace bvc3d::kernels

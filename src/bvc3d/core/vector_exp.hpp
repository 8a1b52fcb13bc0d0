#pragma once
// exp of many arguments at once, for the hot loops that need one or two per LiDAR return.
// SLEEF's deterministic exp (Debian's libsleef, its `cinz` functions: no FMA, u1.0): every instruction
// set (AVX-512, AVX, SSE2, scalar) gives the same bits, each within 1 ulp of the exact value (glibc's
// exp differs from it by 1 ulp in about 1 result in 10).
#include <cstddef>

namespace bvc3d {

// y[i] = exp(x[i]) for i < n (x and y may be the same array).
void vector_exp(const double* x, double* y, std::size_t n);

}  // namespace bvc3d

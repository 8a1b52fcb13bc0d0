#pragma once
// exp and tanh of many arguments at once, for hot loops: exp for the BVC layers (one or two per LiDAR return),
// tanh for the rollouts of navigation (one per place cell and rollout step).
// SLEEF's deterministic functions (Debian's libsleef, its `cinz` functions: no FMA): every instruction set
// (AVX-512, AVX, SSE2, scalar) gives the same bits. exp within 1 ulp of the exact value (u1.0; glibc's exp differs
// from it by 1 ulp in about 1 result in 10); tanh within 3.5 ulp (u3.5: ~6 × faster than its u1.0, which cost as
// much as glibc's tanh).
#include <cstddef>

namespace bvc3d {

// y[i] = exp(x[i]) for i < n (x and y may be the same array).
void vector_exp(const double* x, double* y, std::size_t n);
// y[i] = tanh(x[i]) (within 3.5 ulp) for i < n (x and y may be the same array).
void vector_tanh(const double* x, double* y, std::size_t n);

}  // namespace bvc3d

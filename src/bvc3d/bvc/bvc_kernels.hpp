#pragma once
// The inner loops of the BVC layer, vectorised (see core/simd.hpp).

namespace bvc3d::kernels {

// Adds w[i]·c_r·exp(-(r - (m_lo + n)·Δ)²/2σ²) to rows[i][n] for n < W and every i < count, with the
// profile evaluated as a·b^n·decay[n] (a = c_r·exp(-h x0²), b = exp(2h x0 Δ), decay[n] = exp(-h n²Δ²)).
// decay must hold W rounded up to a multiple of 8 entries; scratch as many; each row must have room
// for as many (the entries past W receive + 0.0, which leaves them unchanged).
void add_distance_profile(double a, double b, const double* decay, int W, const double* w, double* const* rows,
                          int count, double* scratch);

}  // namespace bvc3d::kernels

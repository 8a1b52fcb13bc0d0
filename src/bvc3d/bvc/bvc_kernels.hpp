#pragma once
// The inner loops of the BVC layer, vectorised (see core/simd.hpp).
#include <cstddef>
#include <cstdint>

namespace bvc3d::kernels {

// One return's distance profile c_r·exp(-(r - (m_lo + n)·Δ)²/2σ²), n < W, evaluated as a·b^n·decay[n]
// (a = c_r·exp(-h x0²), b = exp(2h x0 Δ), decay[n] = exp(-h n²Δ²)), to be added with a weight to each of
// `rows` rows; the rows' offsets (into the sums, at m_lo) and weights follow one another in the
// arrays passed to add_distance_profiles.
struct ProfileJob {
    double a, b;
    std::int32_t width, rows;
};

// For each job in turn, in order: sums[offset_i + n] += weight_i·a·b^n·decay[n] for n < width and each
// of its rows i. decay holds the widest width rounded up to a multiple of 8 entries; each row has
// room for as many (the entries past width receive + 0.0, which leaves them unchanged).
void add_distance_profiles(const ProfileJob* jobs, std::size_t n_jobs, const std::uint32_t* offsets,
                           const double* weights, const double* decay, double* sums);

}  // namespace bvc3d::kernels

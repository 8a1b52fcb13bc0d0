#pragma once
// The inner loops of the BVC layer, vectorised (see core/simd.hpp).
#include <cstddef>
#include <cstdint>

#include "bvc3d/bvc/profile_job.hpp"

namespace bvc3d::kernels {

// For each job in turn, in order: sums[offset_i + n] += weight_i·a·b^n·decay[n] for n < width and each
// of its rows i. Widths are multiples of 8 and decay holds the widest; offsets are multiples of 8 into
// 64-byte-aligned sums, so each block of 8 cells is one cache line.
void add_distance_profiles(const ProfileJob* jobs, std::size_t n_jobs, const std::uint32_t* offsets,
                           const double* weights, const double* decay, double* sums);

// For each direction k < n_dir (theta[k] in [0, 2π), padded with NaN to a multiple of 8 entries): the
// first i < n with the smallest |wrap(azimuth[i] - theta[k])| (azimuth[i] in (-π, π]) into best[k]
// (n if there is none) and that gap into gap[k]; best and gap have room for the padding.
void nearest_returns(const double* azimuth, std::size_t n, const double* theta, int n_dir, std::int64_t* best,
                     double* gap);

// The largest of v[0..n) (0 if n is 0); v holds no NaN.
double largest(const double* v, std::size_t n);

}  // namespace bvc3d::kernels

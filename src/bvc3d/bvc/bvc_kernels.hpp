#pragma once
// The inner loops of the BVC layer, vectorised (see core/simd.hpp).
#include <cstddef>
#include <cstdint>

#include "bvc3d/bvc/profile_job.hpp"

namespace bvc3d::kernels {

// For each job in turn, in order: sums[base + dir_d·stride + n] += A_d·a·b^n·decay[n] for n < width
// and each direction d of its record (count at dirs[record], directions at dirs[record + 1 ...],
// factors A_d at factors[record + 1 ...]). Widths are multiples of 8 and decay holds the widest; base and stride are
// multiples of 8 and the sums 64-byte aligned, so each block of 8 cells is one cache line.
void add_distance_profiles(const ProfileJob* jobs, std::size_t n_jobs, const std::uint16_t* dirs,
                           const double* factors, std::size_t stride, const double* decay, double* sums);
// For each direction k < n_dir (theta[k] in [0, 2π), padded with NaN to a multiple of 8 entries): the
// first i < n with the smallest |wrap(azimuth[i] - theta[k])| (azimuth[i] in (-π, π]) into best[k]
// (n if there is none) and that gap into gap[k]; best and gap have room for the padding.
void nearest_returns(const double* azimuth, std::size_t n, const double* theta, int n_dir, std::int64_t* best,
                     double* gap);

// The largest of v[0..n) (0 if n is 0); v holds no NaN.
double largest(const double* v, std::size_t n);

}  // namespace bvc3d::kernels

#pragma once
// The inner loops of the BVC layer, vectorised (see core/simd.hpp).
#include <cstddef>
#include <cstdint>

#include "bvc3d/bvc/profile_job.hpp"

namespace bvc3d::kernels {

// For each job in turn, in order: sums[offset_i + n] += weight_i·a·b^n·decay[n] for n < width and each
// of its rows i. decay holds the widest width rounded up to a multiple of 8 entries; each row has
// room for as many (the entries past width receive + 0.0, which leaves them unchanged).
void add_distance_profiles(const ProfileJob* jobs, std::size_t n_jobs, const std::uint32_t* offsets,
                           const double* weights, const double* decay, double* sums);

}  // namespace bvc3d::kernels

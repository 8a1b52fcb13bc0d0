#pragma once
// The inner loops of the BVC layer, vectorised (see core/simd.hpp).
#include <cstddef>
#include <cstdint>

#include "bvc3d/bvc/profile_job.hpp"
#include "bvc3d/core/simd.hpp"

namespace bvc3d::kernels {

// For each job in turn, in order: sums[base + dir_d·stride + n] += A_d·a·b^n·decay[n] for n < width
// and each direction d of its record (count at dirs[record], directions at dirs[record + 1 ...],
// factors A_d at factors[record + 1 ...]). Widths are multiples of 8 and decay holds the widest; base and stride are
// multiples of 8 and the sums 64-byte aligned, so each block of 8 cells is one cache line.
void add_distance_profiles(const ProfileJob* jobs, std::size_t n_jobs, const std::uint16_t* dirs, const double* factors,
                           std::size_t stride, const double* decay, double* sums);
// For each direction k < n_dir (theta[k] in [0, 2π), padded with NaN to a multiple of 8 entries): the
// first i < n with the smallest |wrap(azimuth[i] - theta[k])| (azimuth[i] in (-π, π]) into best[k]
// (n if there is none) and that gap into gap[k]; best and gap have room for the padding.
void nearest_returns(const double* azimuth, std::size_t n, const double* theta, int n_dir, std::int64_t* best,
                     double* gap);

// What the BVC layer reads of each return before its bookkeeping (boundary_vector_layer.cpp), for up
// to ReturnReadings::size returns at a time: whether it is a return at all, its azimuth wrapped to
// (-π, π] and the azimuth memo's slot for it, and its distance window over the cells m·Δ.
struct ReturnRule {
    double cut;          // m: cells within r ± cut are the window (a superset: an extra cell adds a true term)
    double dd, inv_dd;   // the cells' spacing Δ and 1/Δ (both 0 for a single cell at distance 0)
    int cells;           // n_per_axis: cells 0 .. cells − 1
    bool aligned;        // windows widened to whole blocks of 8 cells (the kernel's recurrence)
    double slot_scale;   // memo slots / 2π
    std::int32_t slots;  // memo slots
};
struct ReturnReadings {
    static constexpr std::size_t size = 64;
    // azimuth: wrapped; x0 = r − first·Δ; width 0: no cell in reach; absent: a NaN or +inf range
    // (no return: the other fields are then meaningless).
    alignas(64) double azimuth[size];
    alignas(64) double x0[size];
    alignas(64) std::int32_t slot[size];
    alignas(64) std::int32_t first[size];
    alignas(64) std::int32_t width[size];
    alignas(64) std::int32_t absent[size];
};
// returns: n ≤ ReturnReadings::size returns of three doubles each (range, azimuth, elevation).
// Returns the index of the first one that is neither absent nor valid (a negative range, a
// non-finite angle), or n; the readings are then complete. Each reading is what the scalar
// formulas give, bit for bit.
std::size_t read_returns(const double* returns, std::size_t n, const ReturnRule& rule, ReturnReadings& out);
// The same compiled for a given instruction set (one this CPU runs): for tests.
std::size_t read_returns(const double* returns, std::size_t n, const ReturnRule& rule, ReturnReadings& out,
                         simd::Isa isa);

// The largest of v[0..n) (0 if n is 0); v holds no NaN.
double largest(const double* v, std::size_t n);
// v[j] = v[j] / by for j < n (a division each, as written: the same bits on every instruction set).
void divide(double* v, std::size_t n, double by);

}  // namespace bvc3d::kernels

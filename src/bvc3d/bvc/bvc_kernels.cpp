#include "bvc3d/bvc/bvc_kernels.hpp"

#include <array>
#include <cmath>
#include <numbers>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/simd.hpp"

namespace bvc3d::kernels {

namespace {

// The first eight powers b^0..b^7 from a product tree, built in registers (a vector loaded from eight
// scalar stores would wait for them to reach the cache: store forwarding cannot merge them).
template <int N, class V>
[[gnu::always_inline]] inline std::array<V, 8 / N> powers(double b, double b2, double b4) {
    const double b3 = b2 * b, b5 = b4 * b, b6 = b4 * b2, b7 = b4 * b3;
    if constexpr (N == 8) return {V{1.0, b, b2, b3, b4, b5, b6, b7}};
    else if constexpr (N == 4) return {V{1.0, b, b2, b3}, V{b4, b5, b6, b7}};
    else return {V{1.0, b}, V{b2, b3}, V{b4, b5}, V{b6, b7}};
}

// One job's blocks, added to the rows of its record's directions: C of them (C = 0: `count`, read at
// run time). With the count known at compile time the direction loop is unrolled: no branch inside a
// block whose outcome changes from job to job (docs/performance.md#kernel-choices-and-the-measurements-behind-them).
template <int N, int C>
[[gnu::always_inline]] inline void add_blocks(std::array<typename simd::doubles<N>::type, 8 / N> pw, double b8, int W,
                                              int count, const std::uint16_t* dir, const double* factor,
                                              std::size_t stride, const double* decay, double* base) {
    using V = typename simd::doubles<N>::type;
    constexpr int P = 8 / N;
    if constexpr (C > 0) count = C;
    for (int n = 0; n < W; n += 8) {
        V u[P];
        for (int p = 0; p < P; ++p) {
            V dec;
            simd::load(dec, decay + n + p * N);
            u[p] = pw[p] * dec;
        }
        for (int i = 0; i < count; ++i) {
            double* row = base + dir[i] * stride + n;
            const double w = factor[i];
            for (int p = 0; p < P; ++p) {
                V r;
                simd::load(r, row + p * N);
                r += w * u[p];
                simd::store(row + p * N, r);
            }
        }
        for (int p = 0; p < P; ++p) pw[p] *= b8;
    }
}

// The kernel for vectors of N doubles (8 on AVX-512, 4 on AVX2, 2 on the baseline): each block of 8
// cells is 8/N vectors. Every lane does the same operations whatever N, so the results are the same
// bits on every instruction set.
template <int N>
[[gnu::always_inline]] inline void profiles(const ProfileJob* jobs, std::size_t n_jobs, const std::uint16_t* dirs,
                                            const double* factors, std::size_t stride, const double* decay,
                                            double* sums) {
    using V = typename simd::doubles<N>::type;
    constexpr int P = 8 / N;
    for (std::size_t j = 0; j < n_jobs; ++j) {
        const ProfileJob& job = jobs[j];
        const double a = job.a, b = job.b;
        // Eight independent chains a·b^(n+t), t = 0..7, stepped by b^8; the first powers come from a
        // product tree (three multiplications deep rather than eight).
        const double b2 = b * b, b4 = b2 * b2, b8 = b4 * b4;
        std::array<V, P> pw = powers<N, V>(b, b2, b4);
        for (int p = 0; p < P; ++p) pw[p] *= a;
        const int W = job.width, count = dirs[job.record];
        const std::uint16_t* dir = dirs + job.record + 1;
        const double* factor = factors + job.record + 1;
        double* base = sums + job.base;
        switch (count) {
            case 1:
                add_blocks<N, 1>(pw, b8, W, count, dir, factor, stride, decay, base);
                break;
            case 2:
                add_blocks<N, 2>(pw, b8, W, count, dir, factor, stride, decay, base);
                break;
            case 3:
                add_blocks<N, 3>(pw, b8, W, count, dir, factor, stride, decay, base);
                break;
            default:
                add_blocks<N, 0>(pw, b8, W, count, dir, factor, stride, decay, base);
        }
    }
}

#if BVC3D_HAVE_DISPATCH
BVC3D_TARGET_V4 void profiles_v4(const ProfileJob* jobs, std::size_t n_jobs, const std::uint16_t* dirs,
                                 const double* factors, std::size_t stride, const double* decay, double* sums) {
    profiles<8>(jobs, n_jobs, dirs, factors, stride, decay, sums);
}
BVC3D_TARGET_V3 void profiles_v3(const ProfileJob* jobs, std::size_t n_jobs, const std::uint16_t* dirs,
                                 const double* factors, std::size_t stride, const double* decay, double* sums) {
    profiles<4>(jobs, n_jobs, dirs, factors, stride, decay, sums);
}
#endif

}  // namespace

// One call per batch of a few hundred returns (not one per return): the dispatch and the loop setup are
// paid once, and the profile goes from registers straight into the rows.
void add_distance_profiles(const ProfileJob* jobs, std::size_t n_jobs, const std::uint16_t* dirs, const double* factors,
                           std::size_t stride, const double* decay, double* sums) {
#if BVC3D_HAVE_DISPATCH
    switch (simd::isa()) {
        case simd::Isa::v4:
            return profiles_v4(jobs, n_jobs, dirs, factors, stride, decay, sums);
        case simd::Isa::v3:
            return profiles_v3(jobs, n_jobs, dirs, factors, stride, decay, sums);
        case simd::Isa::baseline:
            break;
    }
#endif
    profiles<2>(jobs, n_jobs, dirs, factors, stride, decay, sums);
}

BVC3D_DISPATCH
void nearest_returns(const double* azimuth, std::size_t n, const double* theta, int n_dir, std::int64_t* best,
                     double* gap) {
    typedef std::int64_t i8 __attribute__((vector_size(64)));
    using simd::d8;
    const d8 pi = {std::numbers::pi, std::numbers::pi, std::numbers::pi, std::numbers::pi,
                   std::numbers::pi, std::numbers::pi, std::numbers::pi, std::numbers::pi};
    const d8 two_pi = pi + pi, zero = pi - pi;
    for (int k = 0; k < n_dir; k += 8) {  // eight directions at once; a NaN lane is never nearer
        d8 th, nearest = zero + INFINITY;
        simd::load(th, theta + k);
        i8 which = (i8{} + static_cast<std::int64_t>(n));
        for (std::size_t i = 0; i < n; ++i) {
            d8 g = azimuth[i] - th;  // in (-3π, π]: one correction wraps it
            g = g <= -pi ? g + two_pi : g;
            g = g < zero ? -g : g;
            const auto nearer = g < nearest;
            nearest = nearer ? g : nearest;
            which = nearer ? (i8{} + static_cast<std::int64_t>(i)) : which;
        }
        simd::store(gap + k, nearest);
        simd::store(best + k, which);
    }
}

namespace {

// The ranges, azimuths and elevations of L returns (3·L consecutive doubles) as vectors of L lanes.
template <class V>
[[gnu::always_inline]] inline void fields(const double* p, V& range, V& azimuth, V& elevation) {
    constexpr int L = sizeof(V) / sizeof(double);
    if constexpr (L == 8) {
        V v0, v1, v2;
        simd::load(v0, p);
        simd::load(v1, p + 8);
        simd::load(v2, p + 16);
        const V r = __builtin_shufflevector(v0, v1, 0, 3, 6, 9, 12, 15, 0, 0);
        const V a = __builtin_shufflevector(v0, v1, 1, 4, 7, 10, 13, 0, 0, 0);
        const V e = __builtin_shufflevector(v0, v1, 2, 5, 8, 11, 14, 0, 0, 0);
        range = __builtin_shufflevector(r, v2, 0, 1, 2, 3, 4, 5, 10, 13);
        azimuth = __builtin_shufflevector(a, v2, 0, 1, 2, 3, 4, 8, 11, 14);
        elevation = __builtin_shufflevector(e, v2, 0, 1, 2, 3, 4, 9, 12, 15);
    } else {
        for (int k = 0; k < L; ++k) {
            range[k] = p[3 * k];
            azimuth[k] = p[3 * k + 1];
            elevation[k] = p[3 * k + 2];
        }
    }
}

[[gnu::always_inline]] inline std::int32_t slot_of(double wrapped, const ReturnRule& rule) {
    const auto s = static_cast<std::int32_t>((wrapped + std::numbers::pi) * rule.slot_scale);
    return s < rule.slots ? s : rule.slots - 1;
}

// read_returns, compiled for each instruction set (see read_returns.inc).
#if BVC3D_HAVE_DISPATCH
#pragma GCC push_options
#pragma GCC target("arch=x86-64-v4")
namespace v4 {
constexpr int lanes = 8;
#include "bvc3d/bvc/read_returns.inc"
}  // namespace v4
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("arch=x86-64-v3")
namespace v3 {
constexpr int lanes = 4;
#include "bvc3d/bvc/read_returns.inc"
}  // namespace v3
#pragma GCC pop_options
#endif
namespace baseline {
constexpr int lanes = 2;
#include "bvc3d/bvc/read_returns.inc"
}  // namespace baseline
}  // namespace

std::size_t read_returns(const double* returns, std::size_t n, const ReturnRule& rule, ReturnReadings& out) {
    return read_returns(returns, n, rule, out, simd::isa());
}

std::size_t read_returns(const double* returns, std::size_t n, const ReturnRule& rule, ReturnReadings& out,
                         simd::Isa isa) {
#if BVC3D_HAVE_DISPATCH
    switch (isa) {
        case simd::Isa::v4:
            return v4::read_returns(returns, n, rule, out);
        case simd::Isa::v3:
            return v3::read_returns(returns, n, rule, out);
        case simd::Isa::baseline:
            break;
    }
#else
    (void)isa;
#endif
    return baseline::read_returns(returns, n, rule, out);
}

BVC3D_DISPATCH
double largest(const double* v, std::size_t n) {
    if (n == 0) return 0.0;
    simd::d8 m = {v[0], v[0], v[0], v[0], v[0], v[0], v[0], v[0]};
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        simd::d8 x;
        simd::load(x, v + i);
        m = x > m ? x : m;
    }
    double best = m[0];
    for (int k = 1; k < 8; ++k) best = m[k] > best ? m[k] : best;
    for (; i < n; ++i) best = v[i] > best ? v[i] : best;
    return best;
}

BVC3D_DISPATCH
void divide(double* v, std::size_t n, double by) {
    for (std::size_t j = 0; j < n; ++j) v[j] = v[j] / by;
}

}  // namespace bvc3d::kernels

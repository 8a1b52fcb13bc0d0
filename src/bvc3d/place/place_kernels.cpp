#include "bvc3d/place/place_kernels.hpp"

#include <cstdint>
#include <vector>

#include "bvc3d/core/simd.hpp"

namespace bvc3d::kernels {

using simd::f8;

namespace {
template <class V>
inline float reduce8(const V& acc, int f) {
    return ((acc[f] + acc[f + 1]) + (acc[f + 2] + acc[f + 3])) +
           ((acc[f + 4] + acc[f + 5]) + (acc[f + 6] + acc[f + 7]));
}

typedef std::uint32_t bits8 __attribute__((vector_size(32)));  // the bits of an f8

template <int N>
struct floats {
    typedef float type __attribute__((vector_size(4 * N)));
};

// Columns 8b..8b+7 of v as the vector that multiplies a pair's block: twice over (16 lanes, both rows
// of the pair) or once (8 lanes, one row).
template <int N>
[[gnu::always_inline]] inline void columns(typename floats<N>::type& out, const float* v) {
    f8 x;
    simd::load(x, v);
    if constexpr (N == 16) out = __builtin_shufflevector(x, x, 0, 1, 2, 3, 4, 5, 6, 7, 0, 1, 2, 3, 4, 5, 6, 7);
    else out = x;
}

// The blocks of 8 columns (their first column) where some v_t, t < steps, is not 0, in order; returns how many. A
// block that is 0 in every step adds w·0 = ±0 to each sum: a running sum from +0 is never −0 in round-to-nearest, and
// adding ±0 to it leaves its bits as they are, so skipping the block changes no sum (the weights are finite).
[[gnu::always_inline]] inline int nonzero_blocks(const float* v, std::size_t v_stride, std::size_t n, int steps,
                                                 std::uint32_t* blocks) {
    int count = 0;
    for (std::size_t b = 0; b < n; b += 8) {
        bits8 any = {0, 0, 0, 0, 0, 0, 0, 0};
        for (int t = 0; t < steps; ++t) {
            bits8 x;
            simd::load(x, v + t * v_stride + b);
            any |= x;
        }
        blocks[count] = static_cast<std::uint32_t>(b);
        count += !simd::all_zero(any & 0x7fffffff);  // ±0 (a NaN is not 0)
    }
    return count;
}

// T steps × P pairs (2P rows) at once, with vectors of N floats (16: a pair's block in one AVX-512
// register; 8: one row's block), over the blocks listed (columns b..b+7 for b in blocks). Each weight
// block is loaded once for the T steps, and the T·2P accumulator chains keep both FP ports busy. Every
// lane does what a one-row, one-step loop of 8 lanes does, whatever N, P and T: the bits do not change.
template <int N, int P, int T, bool Sparse>
[[gnu::always_inline]] inline void tile(const float* W, std::size_t pair_stride, const float* v, std::size_t v_stride,
                                        const std::uint32_t* blocks, int n_blocks, int n_all, float* out,
                                        std::size_t out_stride) {
    using V = typename floats<N>::type;
    constexpr int H = 16 / N;  // vectors per pair block
    V acc[T][P][H];
    for (int t = 0; t < T; ++t)
        for (int p = 0; p < P; ++p)
            for (int h = 0; h < H; ++h) acc[t][p][h] = V{};
    for (int k = 0; k < (Sparse ? n_blocks : n_all); ++k) {
        const std::size_t b = Sparse ? blocks[k] : 8 * static_cast<std::size_t>(k);
        V w[P][H];
        for (int p = 0; p < P; ++p)
            for (int h = 0; h < H; ++h) simd::load(w[p][h], W + p * pair_stride + 2 * b + h * N);
        for (int t = 0; t < T; ++t) {
            V x;
            columns<N>(x, v + t * v_stride + b);
            for (int p = 0; p < P; ++p)
                for (int h = 0; h < H; ++h) acc[t][p][h] += w[p][h] * x;
        }
    }
    for (int t = 0; t < T; ++t)
        for (int p = 0; p < P; ++p) {
            float* o = out + t * out_stride + 2 * p;
            if constexpr (N == 16) {
                o[0] = reduce8(acc[t][p][0], 0);
                o[1] = reduce8(acc[t][p][0], 8);
            } else {
                o[0] = reduce8(acc[t][p][0], 0);
                o[1] = reduce8(acc[t][p][1], 0);
            }
        }
}

// One row of tiles: T steps of every pair, PB pairs at a time, then the pairs left one by one; over the blocks where
// one of the T steps' inputs is not 0 (`blocks`: room for n/8).
template <int N, int PB, int T>
[[gnu::always_inline]] inline void tile_row(const float* W, std::size_t pair_stride, const float* v,
                                            std::size_t v_stride, std::size_t n, int pairs, float* out,
                                            std::size_t out_stride, std::uint32_t* blocks) {
    const int n_blocks = nonzero_blocks(v, v_stride, n, T, blocks), n_all = static_cast<int>(n / 8);
    const auto row = [&]<bool Sparse>() {
        int p = 0;
        for (; p + PB <= pairs; p += PB)
            tile<N, PB, T, Sparse>(W + p * pair_stride, pair_stride, v, v_stride, blocks, n_blocks, n_all, out + 2 * p,
                                   out_stride);
        for (; p < pairs; ++p)
            tile<N, 1, T, Sparse>(W + p * pair_stride, pair_stride, v, v_stride, blocks, n_blocks, n_all, out + 2 * p,
                                  out_stride);
    };
    // Fewer than a quarter of the blocks 0: every block, in the plain loop (the list's indirection would cost more
    // than it saves: docs/performance.md#kernel-choices-and-the-measurements-behind-them).
    if (static_cast<std::size_t>(n_blocks) * 32 > 3 * n) row.template operator()<false>();
    else row.template operator()<true>();
}

// Tiles of TB steps × PB pairs (registers: TB·PB·16/N accumulators), then the steps left one by one,
// PS pairs at a time, so that 6-8 chains are in flight (two FP ports × an add's 3-4 cycles of latency).
template <int N, int PS, int PB, int TB>
[[gnu::always_inline]] inline void products(const float* W, std::size_t pair_stride, const float* v,
                                            std::size_t v_stride, std::size_t n, int pairs, int steps, float* out,
                                            std::size_t out_stride, std::uint32_t* blocks) {
    int t = 0;
    for (; t + TB <= steps && TB > 1; t += TB)
        tile_row<N, PB, TB>(W, pair_stride, v + t * v_stride, v_stride, n, pairs, out + t * out_stride, out_stride,
                            blocks);
    for (; t < steps; ++t)
        tile_row<N, PS, 1>(W, pair_stride, v + t * v_stride, v_stride, n, pairs, out + t * out_stride, out_stride,
                           blocks);
}

#if BVC3D_HAVE_DISPATCH
// AVX-512: 32 registers, a block of 3 pairs × 8 steps takes 24 accumulators (the fastest tile measured,
// docs/performance.md#kernel-choices-and-the-measurements-behind-them); AVX2: 16.
BVC3D_TARGET_V4 void products_v4(const float* W, std::size_t pair_stride, const float* v, std::size_t v_stride,
                                 std::size_t n, int pairs, int steps, float* out, std::size_t out_stride,
                                 std::uint32_t* blocks) {
    products<16, 8, 3, 8>(W, pair_stride, v, v_stride, n, pairs, steps, out, out_stride, blocks);
}
BVC3D_TARGET_V3 void products_v3(const float* W, std::size_t pair_stride, const float* v, std::size_t v_stride,
                                 std::size_t n, int pairs, int steps, float* out, std::size_t out_stride,
                                 std::uint32_t* blocks) {
    products<8, 4, 1, 4>(W, pair_stride, v, v_stride, n, pairs, steps, out, out_stride, blocks);
}
#endif
}  // namespace

void paired_products(const float* W, std::size_t pair_stride, const float* v, std::size_t v_stride, std::size_t n,
                     int pairs, int steps, float* out, std::size_t out_stride) {
    std::vector<std::uint32_t> blocks(n / 8);
#if BVC3D_HAVE_DISPATCH
    switch (simd::isa()) {
        case simd::Isa::v4:
            return products_v4(W, pair_stride, v, v_stride, n, pairs, steps, out, out_stride, blocks.data());
        case simd::Isa::v3:
            return products_v3(W, pair_stride, v, v_stride, n, pairs, steps, out, out_stride, blocks.data());
        case simd::Isa::baseline:
            break;
    }
#endif
    products<8, 4, 1, 2>(W, pair_stride, v, v_stride, n, pairs, steps, out, out_stride, blocks.data());
}

BVC3D_DISPATCH
void mask_products(const std::uint16_t* bits, std::size_t col_words, const float* v, std::size_t n, std::size_t rows,
                   float* lanes, float* out) {
    typedef float f16 __attribute__((vector_size(64)));
    typedef std::int32_t i16 __attribute__((vector_size(64)));
    const std::size_t stride = 16 * col_words;  // floats per lane
    for (std::size_t i = 0; i < 8 * stride; ++i) lanes[i] = 0.0f;
    const i16 shift = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};
    for (std::size_t j = 0; j < n; ++j) {
        const float x = v[j];
        if (x == 0.0f) continue;
        const i16 xs = i16{} + __builtin_bit_cast(std::int32_t, x);  // x's bits in every lane
        float* lane = lanes + (j % 8) * stride;
        const std::uint16_t* column = bits + j * col_words;
        for (std::size_t r = 0; r < col_words; ++r) {
            // x where the bit is set, +0 where it is clear (adding +0 leaves the lane's sum as it is); made with
            // shifts and an AND: GCC 12 lowers a comparison or a select lane by lane on AVX2.
            const i16 set = -((static_cast<std::int32_t>(column[r]) + i16{}) >> shift & 1);  // lane k: bit k
            f16 a;
            simd::load(a, lane + 16 * r);
            a += __builtin_bit_cast(f16, xs & set);
            simd::store(lane + 16 * r, a);
        }
    }
    for (std::size_t i = 0; i < rows; ++i) {
        const float* l = lanes + i;
        out[i] = ((l[0] + l[stride]) + (l[2 * stride] + l[3 * stride])) +
                 ((l[4 * stride] + l[5 * stride]) + (l[6 * stride] + l[7 * stride]));
    }
}

BVC3D_DISPATCH
float paired_row_product(const float* w, const float* v, std::size_t n) {
    f8 acc = {0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t b = 0; b < n; b += 8) {
        f8 a, x;
        simd::load(a, w + 2 * b);
        simd::load(x, v + b);
        acc += a * x;
    }
    return reduce8(acc, 0);
}

BVC3D_DISPATCH
std::size_t to_floats(const double* in, float* out, std::size_t n, float tiny) {
    const f8 lo = {tiny, tiny, tiny, tiny, tiny, tiny, tiny, tiny}, zero = {0, 0, 0, 0, 0, 0, 0, 0};
    simd::d8 bad = {0, 0, 0, 0, 0, 0, 0, 0};  // x − x: 0 for a finite x, NaN otherwise
    std::size_t j = 0;
    for (; j + 8 <= n; j += 8) {
        simd::d8 x;
        simd::load(x, in + j);
        bad += x - x;
        const f8 f = __builtin_convertvector(x, f8);
        simd::store(out + j, ((f < lo) & (f > -lo)) ? zero : f);
    }
    const bool finite = simd::all_zero(bad);
    for (std::size_t i = 0; i < j && !finite; ++i)
        if (!(in[i] - in[i] == 0)) return i;
    for (; j < n; ++j) {
        if (!(in[j] - in[j] == 0)) return j;
        const float f = static_cast<float>(in[j]);
        out[j] = f < tiny && f > -tiny ? 0.0f : f;
    }
    return n;
}

BVC3D_DISPATCH
float sum8(const float* v, std::size_t n) {
    f8 acc = {0, 0, 0, 0, 0, 0, 0, 0};
    for (std::size_t j = 0; j < n; j += 8) {
        f8 a;
        simd::load(a, v + j);
        acc += a;
    }
    return reduce8(acc, 0);
}

BVC3D_DISPATCH
std::size_t membrane_step(float* __restrict s, const float* __restrict drive, std::size_t n, float k, float inhibition,
                          float gain, float* __restrict v, int* __restrict positive, bool* finite) {
    f8 bad = {0, 0, 0, 0, 0, 0, 0, 0};  // s − s: 0 for a finite s, NaN otherwise
    const f8 zero = bad;
    std::size_t j = 0;
    for (; j + 8 <= n; j += 8) {
        f8 x, d;
        simd::load(x, s + j);
        simd::load(d, drive + j);
        x = x + k * (-x + d - inhibition);
        simd::store(s + j, x);
        bad += x - x;
        simd::store(v + j, gain * (x < zero ? zero : x));  // std::max(x, 0): NaN and −0 stay
    }
    bool ok = simd::all_zero(bad);
    for (; j < n; ++j) {
        s[j] = s[j] + k * (-s[j] + drive[j] - inhibition);
        ok = ok && s[j] - s[j] == 0;
        v[j] = gain * (s[j] < 0.0f ? 0.0f : s[j]);
    }
    *finite = ok;
    std::size_t count = 0;
    for (std::size_t i = 0; i < n; ++i) {
        positive[count] = static_cast<int>(i);
        count += s[i] > 0.0f;
    }
    return count;
}

BVC3D_DISPATCH
bool oja_row(float* __restrict w, const float* __restrict v, float a, float c, float tiny, std::size_t n) {
    const f8 lo = {tiny, tiny, tiny, tiny, tiny, tiny, tiny, tiny}, zero = {0, 0, 0, 0, 0, 0, 0, 0};
    f8 bad = zero;  // x − x: 0 for a finite x, NaN otherwise
    for (std::size_t j = 0; j < n; j += 8) {
        f8 x, b;
        simd::load(x, w + 2 * j);
        simd::load(b, v + j);
        x = x + a * (b - c * x);
        bad += x - x;
        simd::store(w + 2 * j, ((x < lo) & (x > -lo)) ? zero : x);  // NaN stays NaN
    }
    return simd::all_zero(bad);
}

}  // namespace bvc3d::kernels

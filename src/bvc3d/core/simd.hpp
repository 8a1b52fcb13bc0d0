#pragma once
// Runtime dispatch for hot loops: the function is compiled for x86-64-v4 (AVX-512), -v3 (AVX2)
// and the baseline, and the loader picks the best the CPU runs. The binary still runs on any
// x86-64. Kernels under this attribute keep lanes independent and the build forbids FMA
// contraction (-ffp-contract=off), so every clone computes bit-identical results.
// GCC 12 can lower vector comparisons lane by lane under target_clones or in a body inlined into a
// target function (it did for read_returns' 64-bit masks); such a kernel is compiled once per
// instruction set under `#pragma GCC target` instead (bvc/read_returns.inc). Check with objdump.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(BVC3D_NO_DISPATCH)
#define BVC3D_DISPATCH __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#define BVC3D_TARGET_V4 __attribute__((target("arch=x86-64-v4")))
#define BVC3D_TARGET_V3 __attribute__((target("arch=x86-64-v3")))
#define BVC3D_HAVE_DISPATCH 1
#else
#define BVC3D_DISPATCH
#define BVC3D_HAVE_DISPATCH 0
#endif

#include <cstddef>

namespace bvc3d::simd {

// Explicit 8-lane vectors (GCC vector extensions): element-wise arithmetic that each clone lowers
// to its own instructions. Loads and stores are unaligned (memcpy compiles to one move); vectors
// travel by reference so that no function has a vector in its ABI.
typedef float f8 __attribute__((vector_size(32)));
typedef double d8 __attribute__((vector_size(64)));

// Vectors of N doubles, for kernels written once for every width (see isa()): GCC lowers a vector
// wider than the target's registers through the stack, so each clone gets the width it has.
template <int N>
struct doubles {
    typedef double type __attribute__((vector_size(8 * N)));
};

template <class V, class T>
inline void load(V& v, const T* p) {
    __builtin_memcpy(&v, p, sizeof v);
}
template <class V, class T>
inline void store(T* p, const V& v) {
    __builtin_memcpy(p, &v, sizeof v);
}

// Whether every lane of v is 0 (a NaN lane is not), lane by lane: once per call, after a loop.
template <class V>
inline bool all_zero(const V& v) {
    bool all = true;
    for (std::size_t k = 0; k < sizeof v / sizeof v[0]; ++k) all = all && v[k] == 0;
    return all;
}

// The instruction set target_clones would pick on this CPU, for kernels that instantiate a
// width-generic body per instruction set themselves (BVC3D_TARGET_V4/V3 functions).
enum class Isa { baseline, v3, v4 };
inline Isa isa() {
#if BVC3D_HAVE_DISPATCH
    static const Isa chosen = [] {
        __builtin_cpu_init();
        if (__builtin_cpu_supports("x86-64-v4")) return Isa::v4;
        if (__builtin_cpu_supports("x86-64-v3")) return Isa::v3;
        return Isa::baseline;
    }();
    return chosen;
#else
    return Isa::baseline;
#endif
}

}  // namespace bvc3d::simd

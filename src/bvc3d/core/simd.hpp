#pragma once
// Runtime dispatch for hot loops: the function is compiled for x86-64-v4 (AVX-512), -v3 (AVX2)
// and the baseline, and the loader picks the best the CPU runs. The binary still runs on any
// x86-64. Kernels under this attribute keep lanes independent and the build forbids FMA
// contraction (-ffp-contract=off), so every clone computes bit-identical results.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(BVC3D_NO_DISPATCH)
#define BVC3D_DISPATCH __attribute__((target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")))
#else
#define BVC3D_DISPATCH
#endif

namespace bvc3d::simd {

// Explicit 8-lane vectors (GCC vector extensions): element-wise arithmetic that each clone lowers
// to its own instructions. Loads and stores are unaligned (memcpy compiles to one move); vectors
// travel by reference so that no function has a vector in its ABI.
typedef float f8 __attribute__((vector_size(32)));
typedef double d8 __attribute__((vector_size(64)));

template <class V, class T>
inline void load(V& v, const T* p) { __builtin_memcpy(&v, p, sizeof v); }
template <class V, class T>
inline void store(T* p, const V& v) { __builtin_memcpy(p, &v, sizeof v); }

}  // namespace bvc3d::simd

#pragma once
// The cosine search's kernel (analysis/cosine_search.cpp), compiled for each instruction set; private
// to the library (not installed), declared here for the tests that compare the instruction sets.
#include <cstddef>

#include "bvc3d/core/simd.hpp"

namespace bvc3d::analysis::kernels {

// out[i·out_stride + j] = q_i · t_j for the `rows` (1 to 4) query rows at q and the n template rows at t
// (rows `stride` floats apart, a multiple of 16, zero-padded), on instruction set `isa` (one this CPU
// runs). The same bits on every instruction set.
void dots(const float* q, std::size_t rows, const float* t, std::size_t n, std::size_t stride, float* out,
          std::size_t out_stride, simd::Isa isa);

}  // namespace bvc3d::analysis::kernels

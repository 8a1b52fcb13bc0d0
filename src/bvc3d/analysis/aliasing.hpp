#pragma once
// Spatial aliasing (docs/analysis.md): how similar the population vector of each bin is to those
// of bins farther than d_th away. SAI_i = (1/N) Σ_{j≠i, |c_i − c_j| > d_th} cos(a_i, a_j), cos = 0
// when either vector is zero, N = number of bins; MSAI = mean SAI.
// Takes: bin centers (N × D, D = 1..3) and maps (bins × cells). Gives: SAI per bin and MSAI.
#include "bvc3d/analysis/types.hpp"

namespace bvc3d::analysis {

struct AliasingResult {
    Eigen::VectorXd sai;  // per bin
    double msai = 0;      // NaN with no bins
};

// Distances are sqrt(dx² + dy² [+ dz²]) in double, the same expression a numpy double loop evaluates.
// Computed as (â_i · Σ_j â_j − Σ_{|c_i − c_j| <= d_th} â_i · â_j) / N with unit rows â, the near
// bins found with a uniform grid and the dot products over â_i's non-zero cells.
// fixed_n > 0 divides by that number instead of N, in SAI_i and in MSAI = Σ SAI_i / fixed_n (so
// MSAI = Σ_i Σ_j cos / fixed_n², the authors' code with fixed_n = 2662).
AliasingResult spatial_aliasing(const Eigen::Ref<const Centers>& centers, const Eigen::Ref<const RowMatrixXd>& maps,
                                double d_th = 2.0, std::size_t fixed_n = 0);

}  // namespace bvc3d::analysis

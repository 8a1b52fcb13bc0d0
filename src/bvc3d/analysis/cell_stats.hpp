#pragma once
// Per-cell figures that users of place-cell tools expect, from a trial's rate maps.
// Takes: RateMaps (bins with their sample counts, mean and normalized maps). Gives: per cell,
// peak and mean rate, field area and Skaggs spatial information.
#include <vector>

#include "bvc3d/analysis/rate_maps.hpp"

namespace bvc3d::analysis {

struct CellStats {
    std::vector<double> peak_rate;   // maximum of the mean-rate map
    std::vector<double> mean_rate;   // λ̄ = Σ_b p_b λ_b, p_b = occupancy = count_b / binned samples
    std::vector<double> field_area;  // m²: bins whose normalized map value is > 0.5, times the bin area
    // Skaggs et al. (1993): Σ_b p_b λ_b log2(λ_b / λ̄), bits per sample (rates are per sample);
    // terms with λ_b <= 0 add nothing; 0 when λ̄ <= 0.
    std::vector<double> spatial_info;
    // The same divided by λ̄: bits per unit of rate (Skaggs' "bits per spike"); NaN when λ̄ <= 0.
    std::vector<double> spatial_info_per_rate;
};

CellStats cell_stats(const RateMaps& maps);

}  // namespace bvc3d::analysis

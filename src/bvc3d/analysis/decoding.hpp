#pragma once
// Localisation error (SPEC §8): rate maps from the first half of the samples are the templates;
// each sample of the second half is decoded to the bin whose template is most cosine-similar to
// the sample's population vector, and the error is the distance from the sample's true position to
// that bin's centre.
// Takes: positions and rates (one row per sample). Gives: median and mean error in metres.
#include <cstddef>
#include <limits>
#include <optional>
#include <span>

#include "bvc3d/analysis/hexbin.hpp"

namespace bvc3d::analysis {

struct DecodingParams {
    int gridsize = 50;
    std::optional<Extent> extent;  // default: the min/max of all samples (the trial's grid)
};

struct DecodingResult {
    double median_m = std::numeric_limits<double>::quiet_NaN();  // over decoded samples
    double mean_m = std::numeric_limits<double>::quiet_NaN();
    std::size_t n_decoded = 0;    // second-half samples that were decoded
    std::size_t n_undecoded = 0;  // second-half samples with no positive similarity to any template
};

// Choices (docs/analysis.md):
// - Templates are the raw mean rates per bin (matplotlib's hexbin means of the first half), not the
//   thresholded, normalised maps: a template is then the expected population vector at that place,
//   in the same units as the vector being decoded, and no cell's weight is rescaled.
// - The grid is the one the whole trial's rate maps use (extent from all samples unless given);
//   only bins visited in the first half have templates.
// - A sample whose best cosine similarity is not positive (an all-zero population vector, or one
//   that shares no active cell with any template) is not decoded; it is counted in n_undecoded and
//   left out of the median and mean. Ties go to the first bin in matplotlib's order.
template <class T>
DecodingResult decoding_error(std::span<const double> x, std::span<const double> y,
                              const Eigen::Ref<const RowMatrixX<T>>& rates, const DecodingParams& params = {});

// The same decoder with a given grid (analyze_trial shares the rate maps' grid).
template <class T>
DecodingResult decoding_error(const HexGrid& grid, std::span<const double> x, std::span<const double> y,
                              const Eigen::Ref<const RowMatrixX<T>>& rates);

}  // namespace bvc3d::analysis

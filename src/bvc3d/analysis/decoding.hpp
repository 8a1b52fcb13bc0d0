#pragma once
// Localization error (docs/analysis.md): rate maps from the first half of the samples are the
// templates; each sample of the second half is decoded to the bin whose template is most
// cosine-similar to the sample's population vector, and the error is the distance from the
// sample's true position to that bin's center.
// Takes: positions (N × D, or x and y) and rates (one row per sample). Gives: median and mean error in meters.
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "bvc3d/analysis/hexbin.hpp"

namespace bvc3d::analysis {

// What a bin's template is.
enum class DecodingTemplates {
    // docs/model-reference.md#analysis (default): the first half's rate maps, thresholded at each cell's quantile and
    // normalized to a maximum of 1 per cell
    rate_maps,
    means,  // option: the first half's raw mean rates per bin (hexbin means), no threshold or scaling
};
std::string decoding_templates_name(DecodingTemplates t);           // "rate_maps" | "means"
DecodingTemplates parse_decoding_templates(std::string_view name);  // throws InputError otherwise

struct DecodingParams {
    int gridsize = 50;
    double quantile = 0.1;         // rate-map threshold of the templates (unused for `means`)
    std::optional<Extent> extent;  // default: the min/max of all samples (the trial's grid)
    DecodingTemplates templates = DecodingTemplates::rate_maps;
};

struct DecodingResult {
    double median_m = std::numeric_limits<double>::quiet_NaN();  // over decoded samples
    double mean_m = std::numeric_limits<double>::quiet_NaN();
    std::size_t n_decoded = 0;    // second-half samples that were decoded
    std::size_t n_undecoded = 0;  // second-half samples with no positive similarity to any template
    // 3-D positions only (NaN otherwise): the error's horizontal (x, y) and vertical (z) parts, and
    // the median vertical error of chance: a decoder that ignores the rates and picks a first-half
    // bin at random, each with the weight of its first-half samples (the weighted median over every
    // second-half sample and bin; docs/flying.md#analysis).
    double median_horizontal_m = std::numeric_limits<double>::quiet_NaN();
    double mean_horizontal_m = std::numeric_limits<double>::quiet_NaN();
    double median_vertical_m = std::numeric_limits<double>::quiet_NaN();
    double mean_vertical_m = std::numeric_limits<double>::quiet_NaN();
    double median_vertical_chance_m = std::numeric_limits<double>::quiet_NaN();

    // Over every second-half sample, an undecoded one counted at its chance error: the mean distance
    // from its true position to the first half's template bins, each weighted by the number of
    // first-half samples in it (the expected error of a guess drawn from the first half's occupancy).
    double median_all_m = std::numeric_limits<double>::quiet_NaN();
    double mean_all_m = std::numeric_limits<double>::quiet_NaN();

    double frac_undecoded() const {
        const std::size_t n = n_decoded + n_undecoded;
        return n ? static_cast<double>(n_undecoded) / static_cast<double>(n) : std::numeric_limits<double>::quiet_NaN();
    }
};

// Choices (docs/analysis.md):
// - The grid is the one the whole trial's rate maps use (extent from all samples unless given);
//   only bins visited in the first half have templates, and with `rate_maps` the quantile is taken
//   over those bins.
// - A sample whose best cosine similarity is not positive (an all-zero population vector, or one
//   that shares no active cell with any template) is not decoded; it is counted in n_undecoded and
//   left out of the median and mean, and counted at its chance error in median_all and mean_all.
//   Ties go to the first bin in matplotlib's order.
// - Needs at least 2 samples (InputError otherwise); analyze_trial reports fewer as undecoded.
template <class T>
DecodingResult decoding_error(std::span<const double> x, std::span<const double> y,
                              const Eigen::Ref<const RowMatrixX<T>>& rates, const DecodingParams& params = {});

// The same decoder on any grid (analyze_trial shares the rate maps' grid); positions have
// grid.dims() columns and errors are Euclidean distances in that many dimensions.
template <class T>
DecodingResult decoding_error(const Grid& grid, const Eigen::Ref<const Points>& positions,
                              const Eigen::Ref<const RowMatrixX<T>>& rates, DecodingTemplates templates,
                              double quantile);

}  // namespace bvc3d::analysis

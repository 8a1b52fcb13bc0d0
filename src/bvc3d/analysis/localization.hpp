#pragma once
// Localization on recordings (docs/analysis.md#localization-on-recordings): each query is decoded
// to the position of the template whose population vector (BVC or place-cell rates) is most
// cosine-similar; the error is the horizontal distance (and, apart, the vertical one) between the
// query's position and the decoded one; chance (a uniformly random template) and the best possible
// (the nearest template) are reported next to it.
// Takes: template and query rates (one row each) with positions (x, y, z rows). Gives: per query
// the decoded template and errors, and summaries.
#include <cstddef>
#include <limits>
#include <vector>

#include "bvc3d/analysis/types.hpp"

namespace bvc3d::analysis {

struct ErrorSummary {
    double median = std::numeric_limits<double>::quiet_NaN();     // m
    double mean = std::numeric_limits<double>::quiet_NaN();       // m
    double within_1m = std::numeric_limits<double>::quiet_NaN();  // fraction
    double within_2m = std::numeric_limits<double>::quiet_NaN();
};

struct LocalizationResult {
    // Per query: the decoded template (-1 when undecoded), its cosine similarity, the horizontal
    // and vertical errors (NaN when undecoded), and the horizontal distance to the nearest template.
    std::vector<long> decoded;
    std::vector<double> similarity, error, vertical_error, nearest_error;
    std::size_t n_undecoded = 0;
    ErrorSummary decoded_summary;  // over the decoded queries
    double vertical_median = std::numeric_limits<double>::quiet_NaN(), vertical_mean = vertical_median;
    ErrorSummary chance;   // a uniformly random template: over every (decoded query, template) pair, exactly
    ErrorSummary nearest;  // the nearest template of each decoded query: the best any decoder can do
};

// Choices: cos = 0 where a vector is all zero; ties go to the lowest template index; a query
// whose best similarity is not positive (all zero, or sharing no active cell with any template)
// is undecoded and left out of every summary (as in the trial decoder). Positions are rows of
// x, y, z. Rates are accumulated in double. InputError for mismatched shapes or no templates.
LocalizationResult localize(const Eigen::Ref<const RowMatrixXf>& templates,
                            const Eigen::Ref<const Points>& template_xyz, const Eigen::Ref<const RowMatrixXf>& queries,
                            const Eigen::Ref<const Points>& query_xyz);

}  // namespace bvc3d::analysis

#pragma once
// Everything SPEC §8 reports for one trial, from its recorded arrays: the entry point for the
// experiment stage and `bvc3d analyze`.
// Takes: positions (x, y) and place-cell rates (samples × cells, float32 as recorded).
// Gives: rate maps, modality per cell and its summary, SAI per bin and MSAI, localisation error,
// per-cell statistics.
#include <optional>
#include <span>
#include <vector>

#include "bvc3d/analysis/aliasing.hpp"
#include "bvc3d/analysis/cell_stats.hpp"
#include "bvc3d/analysis/decoding.hpp"
#include "bvc3d/analysis/modality.hpp"
#include "bvc3d/analysis/rate_maps.hpp"

namespace bvc3d::analysis {

struct AnalysisParams {
    int gridsize = 50;             // hexagons across x
    double quantile = 0.1;         // rate-map threshold
    DbscanParams dbscan;           // eps 1.0 m, min_samples 20
    double d_th = 2.0;             // m, SAI exclusion radius
    std::optional<Extent> extent;  // default: the trial's own trajectory; the arena's for a fixed grid
    DecodingTemplates decoding_templates = DecodingTemplates::rate_maps;  // SPEC §8: the rate maps
    void validate() const;
};

struct TrialMetrics {
    RateMaps maps;
    std::vector<int> modality;  // per cell
    ModalitySummary modality_summary;
    AliasingResult aliasing;
    DecodingResult decoding;    // on the same grid as the maps, with the same quantile
    CellStats cells;
};

// Any number of samples: with none the maps have no bins (MI 0 for every cell, MSAI NaN); with
// fewer than 2 nothing is decoded (NaN errors, n_undecoded = the second half's n − n/2 samples).
template <class T>
TrialMetrics analyze_trial(std::span<const double> x, std::span<const double> y,
                           const Eigen::Ref<const RowMatrixX<T>>& rates, const AnalysisParams& params = {});

}  // namespace bvc3d::analysis

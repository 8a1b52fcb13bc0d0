#pragma once
// Everything the analysis reports for one trial (docs/analysis.md), from its recorded arrays: the
// entry point for the experiment stage and `bvc3d analyze`.
// Takes: positions (N × D: x, y for ground agents, x, y, z for flying ones) and place-cell rates
// (samples × cells, float32 as recorded). Gives: rate maps, modality per cell and its summary, SAI per
// bin and MSAI, localization error, per-cell statistics (and for 3-D, field isotropy);
// metrics.hpp names the scalar metrics.
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "bvc3d/analysis/aliasing.hpp"
#include "bvc3d/analysis/cell_stats.hpp"
#include "bvc3d/analysis/decoding.hpp"
#include "bvc3d/analysis/isotropy.hpp"
#include "bvc3d/analysis/modality.hpp"
#include "bvc3d/analysis/rate_maps.hpp"
#include "bvc3d/analysis/voxels.hpp"
#include "bvc3d/core/params.hpp"

namespace bvc3d::analysis {

struct AnalysisParams {
    int gridsize = 50;             // hexagons across x
    double quantile = 0.1;         // rate-map threshold
    DbscanParams dbscan;           // eps 1.0 m, min_samples 20
    double d_th = 2.0;             // m, SAI exclusion radius
    std::optional<Extent> extent;  // default: the trial's own trajectory; the arena's for a fixed grid
    DecodingTemplates decoding_templates = DecodingTemplates::rate_maps;  // the paper's: the rate maps
    // 3-D positions (docs/flying.md#analysis): cubic voxels of this side, over `volume` (a trial's
    // flight volume) or else over the positions' own bounds. Not keys of the table: 2-D trials'
    // configurations stay as they were.
    double voxel = 0.5;  // m
    std::optional<Box3> volume;
    // Conventions of the authors' analysis code (docs/reproduction.md); at their defaults the paper's.
    double mi_quantile = -1;  // the modality's rate-map threshold; -1: the same as `quantile`
    int skip_samples = 0;     // recorded samples left out at the start
    int msai_bins = 0;        // > 0: SAI and MSAI divide by this fixed number of bins instead of each trial's N

    // The keys (extent aside, which is a rectangle): gridsize, quantile, eps, min_samples, d_th,
    // decoding_templates, mi_quantile, skip_samples, msai_bins.
    static const params::Table<AnalysisParams>& table();
    // The defaults for positions of `dims` coordinates: DBSCAN's min_samples is 20 in 2-D (the
    // paper's) and 10 in 3-D (0.5 m voxels have 33 lattice neighbors within 1 m, the paper's
    // hexagons about 90; docs/flying.md#analysis).
    static AnalysisParams defaults(int dims);
    void validate() const;
    double modality_quantile() const { return mi_quantile < 0 ? quantile : mi_quantile; }
    // The authors' conventions on the paper's parameters: modality thresholded at the 20 %
    // quantile, the first recorded sample dropped, MSAI over a fixed 2662².
    static AnalysisParams authors();
};

struct TrialMetrics {
    int dims = 2;  // coordinates of the positions
    RateMaps maps;
    std::vector<int> modality;  // per cell
    ModalitySummary modality_summary;
    AliasingResult aliasing;
    DecodingResult decoding;  // on the same grid as the maps, with the same quantile
    CellStats cells;
    std::vector<double> isotropy;       // per cell, 3-D positions only (isotropy.hpp); empty in 2-D
    std::vector<std::string> warnings;  // parameters that cannot work at the scale of the bins (scale_warnings)
};

// eps and d_th are metres, set for the paper's 10 m arena: in a much smaller space they cannot work,
// and the metrics they drive come out as numbers without meaning (MSAI 0, no multimodal cell). Says
// so when the visited bins' span (the diagonal of their bounding box) is below d_th (every pair of
// bins is excluded) or below 2·eps (DBSCAN cannot separate two fields); empty otherwise.
std::vector<std::string> scale_warnings(const Points& centers, const AnalysisParams& params);
// DBSCAN finds a field only around a bin with min_samples visited bins within eps (a cell's active bins are
// visited ones). Says so, with the settings to change, when fewer than half of the visited bins have that many:
// bins large for eps (a building binned with the arena's gridsize), or a path that covers lines, not areas.
std::vector<std::string> field_warnings(const Eigen::Ref<const Points>& positions, const RateMaps& maps,
                                        const AnalysisParams& params);
// Decoding reads the first half's maps at the second half's places (n samples): says so when most of the second
// half lies farther than `radius` from every bin the first half visited (a path that does not come back: the error
// measures the path).
std::vector<std::string> decoding_warnings(const RateMaps& maps, std::size_t n, double radius);

// The grid a trial's positions are binned on: hexagons for 2-D positions (gridsize, extent), voxels
// for 3-D ones (voxel, volume); InputError for other dimensions.
std::shared_ptr<const Grid> fit_grid(const Eigen::Ref<const Points>& positions, const AnalysisParams& params);

// Any number of samples: with none the maps have no bins (MI 0 for every cell, MSAI NaN); with
// fewer than 2 nothing is decoded (NaN errors, n_undecoded = the second half's n − n/2 samples).
// params.skip_samples are dropped first; the rest is analyzed as if it were all there was.
template <class T>
TrialMetrics analyze_trial(const Eigen::Ref<const Points>& positions, const Eigen::Ref<const RowMatrixX<T>>& rates,
                           const AnalysisParams& params = {});
template <class T>
TrialMetrics analyze_trial(std::span<const double> x, std::span<const double> y,
                           const Eigen::Ref<const RowMatrixX<T>>& rates, const AnalysisParams& params = {});

}  // namespace bvc3d::analysis

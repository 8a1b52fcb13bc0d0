#include "bvc3d/analysis/trial_metrics.hpp"

#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"

namespace bvc3d::analysis {

void AnalysisParams::validate() const {
    RateMapParams{gridsize, quantile, extent}.validate();
    dbscan.validate();
    if (!(d_th >= 0) || !std::isfinite(d_th))
        throw InputError("d_th must be a finite distance >= 0, got " + std::to_string(d_th));
}

template <class T>
TrialMetrics analyze_trial(std::span<const double> x, std::span<const double> y,
                           const Eigen::Ref<const RowMatrixX<T>>& rates, const AnalysisParams& params) {
    params.validate();
    TrialMetrics m;
    m.maps = rate_maps<T>(x, y, rates, {params.gridsize, params.quantile, params.extent});
    m.modality = modality(m.maps.bins.centers, m.maps.map, params.dbscan);
    m.modality_summary = summarize_modality(m.modality);
    m.aliasing = spatial_aliasing(m.maps.bins.centers, m.maps.map, params.d_th);
    if (x.size() >= 2) {
        m.decoding = decoding_error<T>(m.maps.bins.grid, x, y, rates, params.decoding_templates, params.quantile);
    } else {  // nothing to build templates from: every second-half sample (n - n/2) is undecoded
        m.decoding.n_decoded = 0;
        m.decoding.n_undecoded = x.size() - x.size() / 2;
    }
    m.cells = cell_stats(m.maps);
    return m;
}

template TrialMetrics analyze_trial<float>(std::span<const double>, std::span<const double>,
                                           const Eigen::Ref<const RowMatrixXf>&, const AnalysisParams&);
template TrialMetrics analyze_trial<double>(std::span<const double>, std::span<const double>,
                                            const Eigen::Ref<const RowMatrixXd>&, const AnalysisParams&);

}  // namespace bvc3d::analysis

#include "bvc3d/analysis/trial_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d::analysis {

const params::Table<AnalysisParams>& AnalysisParams::table() {
    using namespace params;
    using A = AnalysisParams;
    static const Table<A> t(
        "analysis",
        {integer("gridsize", &A::gridsize, closed(2, 2000), "hexagons across x (matplotlib's gridsize)"),
         real("quantile", &A::quantile, closed(0, 1), "rate-map threshold: values below this quantile become 0"),
         Field<A>{"eps",
                  "m, DBSCAN neighborhood radius",
                  Kind::real,
                  open_closed(0, 1e6),
                  {},
                  false,
                  0,
                  0,
                  [](const A& a) { return Value(a.dbscan.eps); },
                  [](A& a, const Value& v) { a.dbscan.eps = std::get<double>(v); },
                  false},
         Field<A>{"min_samples",
                  "DBSCAN neighbors (the point included) of a core point",
                  Kind::integer,
                  closed(1, 1e9),
                  {},
                  false,
                  0,
                  0,
                  [](const A& a) { return Value(static_cast<long long>(a.dbscan.min_samples)); },
                  [](A& a, const Value& v) { a.dbscan.min_samples = static_cast<int>(std::get<long long>(v)); },
                  false},
         real("d_th", &A::d_th, closed(0, 1e6), "m, bins nearer than this do not count as aliased"),
         choice("decoding_templates", &A::decoding_templates,
                {{DecodingTemplates::rate_maps, "rate_maps"}, {DecodingTemplates::means, "means"}},
                "rate_maps (thresholded, normalized maps of the first half) or means (raw mean rates)"),
         real("mi_quantile", &A::mi_quantile, closed(-1, 1),
              "the modality's rate-map threshold quantile; -1: the same as quantile")
             .quiet_at_default(),
         integer("skip_samples", &A::skip_samples, closed(0, 1e9), "recorded samples left out at the start")
             .quiet_at_default(),
         integer("msai_bins", &A::msai_bins, closed(0, 1e9),
                 "> 0: SAI and MSAI divide by this many bins instead of the trial's own number")
             .quiet_at_default()});
    return t;
}

AnalysisParams AnalysisParams::defaults(int dims) {
    AnalysisParams p;
    if (dims == 3) p.dbscan.min_samples = 10;
    return p;
}

void AnalysisParams::validate() const {
    table().check(*this);
    if (!(mi_quantile == -1 || (mi_quantile >= 0 && mi_quantile <= 1)))
        table().fail("mi_quantile",
                     "must be -1 (the same as quantile) or in [0, 1], got " + params::to_text(mi_quantile));
    if (extent) extent->validate();
    if (!(voxel > 0) || !std::isfinite(voxel)) throw InputError("analysis: voxel must be a positive length");
    if (volume) volume->validate();
}

AnalysisParams AnalysisParams::authors() {
    AnalysisParams p;
    p.mi_quantile = 0.2;
    p.skip_samples = 1;
    p.msai_bins = 2662;
    return p;
}

std::shared_ptr<const Grid> fit_grid(const Eigen::Ref<const Points>& positions, const AnalysisParams& params) {
    if (positions.cols() == 3)
        return std::make_shared<VoxelGrid>(VoxelGrid::fit(positions, params.voxel, params.volume));
    if (positions.cols() != 2)
        throw InputError("positions with " + std::to_string(positions.cols()) +
                         " coordinates: binning needs 2 (hexagons) or 3 (voxels)");
    const Eigen::VectorXd x = positions.col(0), y = positions.col(1);
    return std::make_shared<HexGrid>(HexGrid::fit({x.data(), static_cast<std::size_t>(x.size())},
                                                  {y.data(), static_cast<std::size_t>(y.size())}, params.gridsize,
                                                  params.extent));
}

std::vector<std::string> scale_warnings(const Points& centers, const AnalysisParams& params) {
    std::vector<std::string> out;
    if (centers.rows() < 2) return out;
    const double span = (centers.colwise().maxCoeff() - centers.colwise().minCoeff()).norm();
    const std::string across = " the visited bins span only " + format_number(std::round(span * 1000) / 1000) + " m";
    if (span < params.d_th)
        out.push_back("analysis: d_th = " + format_number(params.d_th) + " m, but" + across +
                      ": every pair of bins is excluded and the SAI and MSAI mean nothing; give d_th in the "
                      "arena's scale (analysis key d_th)");
    if (span < 2 * params.dbscan.eps)
        out.push_back("analysis: eps = " + format_number(params.dbscan.eps) + " m, but" + across +
                      ": DBSCAN cannot separate two fields, so no cell can be multimodal; give eps in the arena's "
                      "scale (analysis key eps)");
    return out;
}

template <class T>
TrialMetrics analyze_trial(const Eigen::Ref<const Points>& positions, const Eigen::Ref<const RowMatrixX<T>>& rates,
                           const AnalysisParams& params) {
    params.validate();
    if (params.skip_samples > 0 && rates.rows() == positions.rows()) {  // (a mismatch is reported below)
        const Eigen::Index keep = std::max<Eigen::Index>(0, positions.rows() - params.skip_samples);
        AnalysisParams rest = params;
        rest.skip_samples = 0;
        return analyze_trial<T>(positions.bottomRows(keep), rates.bottomRows(keep), rest);
    }
    TrialMetrics m;
    m.dims = static_cast<int>(positions.cols());
    m.maps = rate_maps<T>(fit_grid(positions, params), positions, rates, params.quantile);
    if (params.modality_quantile() == params.quantile) {
        m.modality = modality(m.maps.bins.centers, m.maps.map, params.dbscan);
    } else {  // the same means, thresholded at the modality's own quantile
        RowMatrixXd maps = m.maps.mean;
        threshold_and_normalize(maps, params.modality_quantile());
        m.modality = modality(m.maps.bins.centers, maps, params.dbscan);
    }
    m.modality_summary = summarize_modality(m.modality);
    m.aliasing =
        spatial_aliasing(m.maps.bins.centers, m.maps.map, params.d_th, static_cast<std::size_t>(params.msai_bins));
    const auto n = static_cast<std::size_t>(positions.rows());
    if (n >= 2) {
        m.decoding = decoding_error<T>(*m.maps.grid, positions, rates, params.decoding_templates, params.quantile);
    } else {  // nothing to build templates from: every second-half sample (n - n/2) is undecoded
        m.decoding.n_decoded = 0;
        m.decoding.n_undecoded = n - n / 2;
    }
    m.cells = cell_stats(m.maps);
    if (m.dims == 3) m.isotropy = field_isotropy(m.maps.bins.centers, m.maps.map, m.modality, params.dbscan);
    m.warnings = scale_warnings(m.maps.bins.centers, params);
    return m;
}

template <class T>
TrialMetrics analyze_trial(std::span<const double> x, std::span<const double> y,
                           const Eigen::Ref<const RowMatrixX<T>>& rates, const AnalysisParams& params) {
    return analyze_trial<T>(positions_2d(x, y), rates, params);
}

template TrialMetrics analyze_trial<float>(const Eigen::Ref<const Points>&, const Eigen::Ref<const RowMatrixXf>&,
                                           const AnalysisParams&);
template TrialMetrics analyze_trial<double>(const Eigen::Ref<const Points>&, const Eigen::Ref<const RowMatrixXd>&,
                                            const AnalysisParams&);
template TrialMetrics analyze_trial<float>(std::span<const double>, std::span<const double>,
                                           const Eigen::Ref<const RowMatrixXf>&, const AnalysisParams&);
template TrialMetrics analyze_trial<double>(std::span<const double>, std::span<const double>,
                                            const Eigen::Ref<const RowMatrixXd>&, const AnalysisParams&);

}  // namespace bvc3d::analysis

#include "bvc3d/analysis/trial_metrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <set>
#include <string>

#include "bvc3d/core/angles.hpp"
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
    // No samples: no column taken (a column of an empty Ref with no data is an offset from a null pointer).
    Eigen::VectorXd x(positions.rows()), y(positions.rows());
    if (positions.rows() > 0) x = positions.col(0), y = positions.col(1);
    return std::make_shared<HexGrid>(HexGrid::fit({x.data(), static_cast<std::size_t>(x.size())},
                                                  {y.data(), static_cast<std::size_t>(y.size())}, params.gridsize,
                                                  params.extent));
}

namespace {

// For each center, how many centers lie within `radius` of it (itself included), counted up to `cap`: a hash of
// cubes `radius` wide, whose 3^D neighbours hold every candidate.
std::vector<int> neighbours_within(const Points& c, double radius, int cap) {
    using Cell = std::array<std::int64_t, 3>;
    const auto cell_of = [&](Eigen::Index i) {
        Cell k{0, 0, 0};
        for (Eigen::Index d = 0; d < c.cols() && d < 3; ++d)
            k[static_cast<std::size_t>(d)] = static_cast<std::int64_t>(std::floor(c(i, d) / radius));
        return k;
    };
    std::map<Cell, std::vector<Eigen::Index>> cells;
    for (Eigen::Index i = 0; i < c.rows(); ++i) cells[cell_of(i)].push_back(i);
    const int reach = c.cols() >= 3 ? 1 : 0;
    std::vector<int> count(static_cast<std::size_t>(c.rows()), 0);
    for (Eigen::Index i = 0; i < c.rows(); ++i) {
        const Cell k = cell_of(i);
        int& n = count[static_cast<std::size_t>(i)];
        for (std::int64_t a = -1; a <= 1 && n < cap; ++a)
            for (std::int64_t b = -1; b <= 1 && n < cap; ++b)
                for (std::int64_t z = -reach; z <= reach && n < cap; ++z) {
                    const auto it = cells.find({k[0] + a, k[1] + b, k[2] + z});
                    if (it == cells.end()) continue;
                    for (const Eigen::Index j : it->second)
                        if ((c.row(i) - c.row(j)).norm() <= radius && ++n >= cap) break;
                }
    }
    return count;
}

// The hexagons of the paper's arena: 50 across the 9.2 m its robot's center covers, 28 rows (m²).
constexpr double paper_bin_area = 0.5 * (9.2 / 50) * (9.2 / 28);

}  // namespace

namespace {

// Of the visited bins' neighbour counts within eps (capped at min_samples): how many reach min_samples, and the
// median count.
struct Reach {
    std::size_t cores = 0, bins = 0;
    int median = 0, most = 0;  // visited bins within eps of a visited bin: the median, the most (capped)
};
Reach field_reach(const Points& centers, const DbscanParams& dbscan, int cap) {
    std::vector<int> count = neighbours_within(centers, dbscan.eps, std::max(cap, dbscan.min_samples));
    Reach r;
    r.bins = count.size();
    if (count.empty()) return r;
    r.cores = static_cast<std::size_t>(
        std::count_if(count.begin(), count.end(), [&](int k) { return k >= dbscan.min_samples; }));
    r.most = *std::max_element(count.begin(), count.end());
    std::nth_element(count.begin(), count.begin() + static_cast<std::ptrdiff_t>(count.size() / 2), count.end());
    r.median = count[count.size() / 2];
    return r;
}

// Bins of a grid within eps of a bin, every one visited: a disc's (2-D) or ball's (3-D) measure over a bin's.
double bins_within(const Grid& grid, double eps) {
    const double reach = grid.dims() == 3 ? 4.0 / 3.0 * pi * eps * eps * eps : pi * eps * eps;
    return reach / grid.bin_measure();
}

}  // namespace

std::vector<std::string> field_warnings(const Eigen::Ref<const Points>& positions, const RateMaps& maps,
                                        const AnalysisParams& params) {
    const int need = params.dbscan.min_samples;
    if (maps.bins.size() < 1 || need <= 1) return {};
    const auto cap = [&](const Grid& g) { return static_cast<int>(std::ceil(bins_within(g, params.dbscan.eps))); };
    const Reach now = field_reach(maps.bins.centers, params.dbscan, cap(*maps.grid));
    if (2 * now.cores >= now.bins) return {};  // most of the visited floor can hold a field
    const std::string eps = format_number(params.dbscan.eps);
    std::string text =
        "analysis: min_samples = " + std::to_string(need) + ", but " +
        (now.cores == 0 ? "no visited bin has " + std::to_string(need) + " visited bins within eps = " + eps +
                              " m (at most " + std::to_string(now.most) +
                              "): DBSCAN can find no field, so frac_active is 0 and mean_mi_active and "
                              "frac_multimodal mean nothing"
                        : "only " + format_number(std::round(1000.0 * now.cores / now.bins) / 10) +
                              " % of the visited bins have " + std::to_string(need) +
                              " visited bins within eps = " + eps + " m (half of them " + std::to_string(now.median) +
                              " or fewer): DBSCAN finds no field elsewhere, and the modality metrics say little");
    // Bins much larger than the arena's (a building binned with the arena's gridsize): bins of the arena's size
    // first. Then a min_samples that asks of the path's neighbourhood what the paper's 20 asks of a fully walked
    // one: the same share of the bins within eps (20 of about 100 hexagons within 1 m in the arena).
    const Grid* grid = maps.grid.get();
    std::shared_ptr<const Grid> finer_grid;
    Reach reach = now;
    const double area = grid->bin_measure();
    if (grid->dims() == 2 && area > 2 * paper_bin_area) {
        AnalysisParams finer = params;
        finer.gridsize =
            std::min(2000, static_cast<int>(std::ceil(params.gridsize * std::sqrt(area / paper_bin_area))));
        finer_grid = fit_grid(positions, finer);
        grid = finer_grid.get();
        reach = field_reach(bin_positions(*grid, positions).centers, params.dbscan, cap(*grid));
        text += ". Its hexagons are " + format_number(std::round(area * 1000) / 1000) + " m², the paper's arena's " +
                format_number(std::round(paper_bin_area * 1000) / 1000) +
                " m²: give hexagons of that size (analysis key gridsize: " + std::to_string(finer.gridsize) + ")";
        if (2 * reach.cores >= reach.bins) return {text};
        text +=
            " and, as the path covers lines rather than the floor there too, a min_samples that asks the same "
            "share of the visited bins around a field";
    } else {
        text +=
            ". The path covers lines rather than the floor: give a min_samples that asks the same share of the "
            "visited bins around a field";
    }
    const double share = need / bins_within(*grid, params.dbscan.eps);
    const int fair = std::max(2, static_cast<int>(std::lround(share * reach.median)));
    return {text + " (analysis key min_samples, e.g. " + std::to_string(fair) + ": " + std::to_string(need) +
            " of the " + format_number(std::round(bins_within(*grid, params.dbscan.eps))) +
            " bins within eps, of the " + std::to_string(reach.median) + " a visited bin has there at the median)"};
}

std::vector<std::string> decoding_warnings(const RateMaps& maps, std::size_t n, double radius) {
    if (n < 4 || !(radius > 0)) return {};
    const std::size_t half = n / 2;
    const Points& c = maps.bins.centers;
    // The first half's visited bins, hashed in cubes `radius` wide: a bin within `radius` of a place lies in the
    // place's cube or a neighbouring one.
    using Cell = std::array<std::int64_t, 3>;
    const auto cell_of = [&](int b) {
        Cell k{0, 0, 0};
        for (Eigen::Index d = 0; d < c.cols() && d < 3; ++d)
            k[static_cast<std::size_t>(d)] = static_cast<std::int64_t>(std::floor(c(b, d) / radius));
        return k;
    };
    std::map<Cell, std::vector<int>> seen;
    std::set<int> first;
    for (std::size_t s = 0; s < half; ++s)
        if (const int b = maps.bins.sample_bin[s]; b >= 0 && first.insert(b).second) seen[cell_of(b)].push_back(b);
    const int reach = c.cols() >= 3 ? 1 : 0;
    const auto near_first = [&](int b) {
        const Cell k = cell_of(b);
        for (std::int64_t i = -1; i <= 1; ++i)
            for (std::int64_t j = -1; j <= 1; ++j)
                for (std::int64_t z = -reach; z <= reach; ++z)
                    if (const auto it = seen.find({k[0] + i, k[1] + j, k[2] + z}); it != seen.end())
                        for (const int f : it->second)
                            if ((c.row(b) - c.row(f)).norm() <= radius) return true;
        return false;
    };
    std::size_t away = 0;
    for (std::size_t s = half; s < n; ++s)
        if (const int b = maps.bins.sample_bin[s]; b >= 0 && !near_first(b)) ++away;
    if (2 * away <= n - half) return {};
    return {"decoding: " + format_number(std::round(1000.0 * away / static_cast<double>(n - half)) / 10) +
            " % of the decoded samples (the second half of those recorded) lie farther than " + format_number(radius) +
            " m (eps) from every place the first half visited, where no template can be right: the decoding error "
            "measures where the path went, not the place code; record a path that comes back to its places (e.g. "
            "a tour driven twice while sampling)"};
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
    for (auto& w : field_warnings(positions, m.maps, params)) m.warnings.push_back(std::move(w));
    for (auto& w : decoding_warnings(m.maps, n, params.dbscan.eps)) m.warnings.push_back(std::move(w));
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

#include "bvc3d/analysis/metrics.hpp"

#include <algorithm>
#include <cmath>

namespace bvc3d::analysis {

namespace {

// Median of the values that are not NaN (numpy.median of them; +inf counts), NaN if none.
double median_not_nan(const std::vector<double>& values) {
    std::vector<double> v;
    for (const double x : values)
        if (!std::isnan(x)) v.push_back(x);
    if (v.empty()) return NAN;
    std::sort(v.begin(), v.end());
    const std::size_t k = v.size() / 2;
    return v.size() % 2 ? v[k] : 0.5 * (v[k - 1] + v[k]);
}

double fraction_unimodal(const TrialMetrics& m) {
    if (m.modality.empty()) return NAN;
    return static_cast<double>(std::count(m.modality.begin(), m.modality.end(), 1)) /
           static_cast<double>(m.modality.size());
}

}  // namespace

const std::vector<Metric>& metric_table() {
    static const std::vector<Metric> table{
        {"frac_active", "MI>0 fraction", "fraction of cells with MI > 0",
         "Fraction of place cells with a field (MI > 0)", 3,
         [](const TrialMetrics& m) { return m.modality_summary.frac_active; }},
        {"mean_mi_active", "mean MI (MI>0)", "mean MI of cells with MI > 0", "Mean modality index of active cells", 2,
         [](const TrialMetrics& m) { return m.modality_summary.mean_mi_active; }},
        {"frac_multimodal", "MI>1 fraction", "fraction of cells with MI > 1",
         "Fraction of multimodal place cells (MI > 1)", 3,
         [](const TrialMetrics& m) { return m.modality_summary.frac_multimodal; }},
        {"msai", "MSAI", "MSAI", "Mean spatial aliasing index", 4,
         [](const TrialMetrics& m) { return m.aliasing.msai; }},
        {"decode_median_m", "decoding median (m)", "median decoding error (m)", "Localization error (median)", 2,
         [](const TrialMetrics& m) { return m.decoding.median_m; }},
        {"decode_mean_m", "decoding mean (m)", "mean decoding error (m)", "", 2,
         [](const TrialMetrics& m) { return m.decoding.mean_m; }},
        {"n_bins", "bins", "visited bins", "", -1,
         [](const TrialMetrics& m) { return static_cast<double>(m.maps.bins.size()); }},
        {"n_decoded", "decoded samples", "decoded samples", "", -1,
         [](const TrialMetrics& m) { return static_cast<double>(m.decoding.n_decoded); }},
        {"n_undecoded", "undecoded samples", "undecoded samples", "", -1,
         [](const TrialMetrics& m) { return static_cast<double>(m.decoding.n_undecoded); }},
        // Flying agents (docs/flying.md#analysis).
        {"frac_unimodal", "MI=1 fraction", "fraction of cells with one field (MI = 1)",
         "Fraction of place cells with a single 3-D field (MI = 1)", 3, fraction_unimodal, 3},
        {"isotropy_median", "isotropy (median)", "field isotropy: sd z / mean sd x, y",
         "Isotropy of single 3-D fields (median over MI = 1 cells; bats: about 1)", 2,
         [](const TrialMetrics& m) { return median_not_nan(m.isotropy); }, 3},
        {"decode_horizontal_median_m", "decoding horizontal (m)", "median horizontal decoding error (m)",
         "Horizontal localization error (median)", 2,
         [](const TrialMetrics& m) { return m.decoding.median_horizontal_m; }, 3},
        {"decode_vertical_median_m", "decoding vertical (m)", "median vertical decoding error (m)",
         "Vertical localization error (median)", 2, [](const TrialMetrics& m) { return m.decoding.median_vertical_m; },
         3},
        {"decode_vertical_chance_m", "vertical chance (m)", "median vertical error of a random guess (m)", "", 2,
         [](const TrialMetrics& m) { return m.decoding.median_vertical_chance_m; }, 3},
        // Decoding's coverage: how many samples it left out, and errors that count them at chance.
        {"frac_undecoded", "undecoded fraction", "fraction of samples not decoded",
         "Fraction of second-half samples not decoded", 3,
         [](const TrialMetrics& m) { return m.decoding.frac_undecoded(); }},
        {"decode_median_all_m", "decoding median, all (m)", "median decoding error, undecoded at chance (m)",
         "Localization error (median), undecoded samples at chance", 2,
         [](const TrialMetrics& m) { return m.decoding.median_all_m; }},
        {"decode_mean_all_m", "decoding mean, all (m)", "mean decoding error, undecoded at chance (m)", "", 2,
         [](const TrialMetrics& m) { return m.decoding.mean_all_m; }},
    };
    return table;
}

std::vector<std::string> metric_names(int dims) {
    std::vector<std::string> names;
    for (const auto& m : metric_table())
        if (dims == 0 || m.applies(dims)) names.emplace_back(m.name);
    return names;
}

std::vector<std::pair<std::string, double>> scalar_metrics(const TrialMetrics& m) {
    std::vector<std::pair<std::string, double>> out;
    for (const auto& metric : metric_table())
        if (metric.applies(m.dims)) out.emplace_back(metric.name, metric.value(m));
    return out;
}

}  // namespace bvc3d::analysis

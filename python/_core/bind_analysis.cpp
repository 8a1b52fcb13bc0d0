// Analysis functions (bvc3d._core.analysis): numpy in, C++ (bvc3d::analysis), numpy out.
// Argument checking and documentation live in python/bvc3d/analysis.py.
#include <array>
#include <optional>
#include <span>
#include <string>

#include "bindings.hpp"
#include "bvc3d/analysis/metrics.hpp"
#include "bvc3d/analysis/trial_metrics.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d::py {

namespace {

namespace an = bvc3d::analysis;
template <class T>
using Array = pyb::array_t<T, pyb::array::c_style | pyb::array::forcecast>;
using MaybeExtent = std::optional<std::array<double, 4>>;

std::optional<an::Extent> extent_of(const MaybeExtent& e) {
    if (!e) return std::nullopt;
    return an::Extent{(*e)[0], (*e)[1], (*e)[2], (*e)[3]};
}

std::span<const double> span1d(const ArrayD& a, const char* name) {
    if (a.ndim() != 1)
        throw InputError(std::string(name) + " must be 1-D, got " + std::to_string(a.ndim()) + " dimensions");
    return {a.data(), static_cast<std::size_t>(a.shape(0))};
}

template <class T>
Eigen::Map<const an::RowMatrixX<T>> matrix(const Array<T>& a, const char* name) {
    if (a.ndim() != 2)
        throw InputError(std::string(name) + " must be 2-D, got " + std::to_string(a.ndim()) + " dimensions");
    return {a.data(), a.shape(0), a.shape(1)};
}

Eigen::Map<const an::Points> centers_of(const ArrayD& a) {
    if (a.ndim() != 2 || a.shape(1) < 1 || a.shape(1) > 3)
        throw InputError("centers/points must be an (N, D) array with D = 2 or 3");
    return {a.data(), a.shape(0), a.shape(1)};
}

pyb::array_t<double> numpy_of(const an::RowMatrixXd& m) { return to_numpy(m.data(), {m.rows(), m.cols()}); }
template <class T>
pyb::array_t<T> numpy_of(const std::vector<T>& v) {
    return to_numpy(v.data(), {static_cast<pyb::ssize_t>(v.size())});
}

pyb::dict decoding_dict(const an::DecodingResult& d) {
    pyb::dict r;
    r["median_m"] = d.median_m;
    r["mean_m"] = d.mean_m;
    r["n_decoded"] = d.n_decoded;
    r["n_undecoded"] = d.n_undecoded;
    r["frac_undecoded"] = d.frac_undecoded();
    r["median_all_m"] = d.median_all_m;
    r["mean_all_m"] = d.mean_all_m;
    return r;
}

pyb::dict decoding_dict_3d(const an::DecodingResult& d) {
    pyb::dict r = decoding_dict(d);
    r["median_horizontal_m"] = d.median_horizontal_m;
    r["mean_horizontal_m"] = d.mean_horizontal_m;
    r["median_vertical_m"] = d.median_vertical_m;
    r["mean_vertical_m"] = d.mean_vertical_m;
    r["median_vertical_chance_m"] = d.median_vertical_chance_m;
    return r;
}

using MaybeBox = std::optional<std::array<double, 6>>;
std::optional<an::Box3> box_of(const MaybeBox& b) {
    if (!b) return std::nullopt;
    return an::Box3{(*b)[0], (*b)[1], (*b)[2], (*b)[3], (*b)[4], (*b)[5]};
}

Eigen::Map<const an::Points> positions3(const ArrayD& a) {
    if (a.ndim() != 2 || a.shape(1) != 3) throw InputError("positions must be an (N, 3) array");
    return {a.data(), a.shape(0), 3};
}

pyb::dict summary_dict(const an::ModalitySummary& s) {
    pyb::dict r;
    r["frac_active"] = s.frac_active;
    r["mean_mi_active"] = s.mean_mi_active;
    r["frac_multimodal"] = s.frac_multimodal;
    return r;
}

pyb::dict stats_dict(const an::CellStats& s) {
    pyb::dict r;
    r["peak_rate"] = numpy_of(s.peak_rate);
    r["mean_rate"] = numpy_of(s.mean_rate);
    r["field_area_m2"] = numpy_of(s.field_area);
    r["spatial_info"] = numpy_of(s.spatial_info);
    r["spatial_info_per_rate"] = numpy_of(s.spatial_info_per_rate);
    return r;
}

// A trial's analysis as a dict: maps and their bins, modality, aliasing, decoding and cell
// statistics; the bin's size under `measure_key` (hexagon area or voxel volume).
pyb::dict trial_analysis_dict(const an::TrialMetrics& m, const char* measure_key, pyb::dict decoding) {
    pyb::dict d;
    d["centers"] = numpy_of(m.maps.bins.centers);
    d["counts"] = numpy_of(m.maps.bins.counts);
    d["mean_maps"] = numpy_of(m.maps.mean);
    d["maps"] = numpy_of(m.maps.map);
    d[measure_key] = m.maps.grid->bin_measure();
    d["modality"] = numpy_of(m.modality);
    d["modality_summary"] = summary_dict(m.modality_summary);
    d["sai"] = to_numpy(m.aliasing.sai.data(), {m.aliasing.sai.size()});
    d["msai"] = m.aliasing.msai;
    d["decoding"] = std::move(decoding);
    d["cells"] = stats_dict(m.cells);
    return d;
}

// Functions over per-sample values exist for float32 (taken as is) and float64 (anything else).
template <class T>
void bind_sample_functions(pyb::module_& a) {
    auto values_arg = [](const char* name) {
        auto arg = pyb::arg(name);
        if constexpr (std::is_same_v<T, float>) arg.noconvert();
        return arg;
    };
    a.def(
        "hexbin",
        [](const ArrayD& x, const ArrayD& y, const Array<T>& values, int gridsize, const MaybeExtent& extent) {
            const auto xs = span1d(x, "x"), ys = span1d(y, "y");
            const auto v = matrix<T>(values, "values");
            an::HexBins bins;
            an::RowMatrixXd means;
            interruptible([&](const std::atomic<bool>&) {
                bins = an::hexbin(xs, ys, gridsize, extent_of(extent));
                means = an::bin_means<T>(bins, v);
            });
            return pyb::make_tuple(numpy_of(bins.centers), numpy_of(means), numpy_of(bins.counts));
        },
        pyb::arg("x"), pyb::arg("y"), values_arg("values"), pyb::arg("gridsize"), pyb::arg("extent"));
    a.def(
        "rate_maps",
        [](const ArrayD& x, const ArrayD& y, const Array<T>& rates, int gridsize, double quantile,
           const MaybeExtent& extent) {
            const auto xs = span1d(x, "x"), ys = span1d(y, "y");
            const auto r = matrix<T>(rates, "rates");
            an::RateMaps m;
            interruptible([&](const std::atomic<bool>&) {
                m = an::rate_maps<T>(xs, ys, r, {gridsize, quantile, extent_of(extent)});
            });
            return pyb::make_tuple(numpy_of(m.bins.centers), numpy_of(m.map), numpy_of(m.mean),
                                   numpy_of(m.bins.counts));
        },
        pyb::arg("x"), pyb::arg("y"), values_arg("rates"), pyb::arg("gridsize"), pyb::arg("quantile"),
        pyb::arg("extent"));
    a.def(
        "decoding_error",
        [](const ArrayD& x, const ArrayD& y, const Array<T>& rates, int gridsize, const MaybeExtent& extent,
           double quantile, const std::string& templates) {
            const auto xs = span1d(x, "x"), ys = span1d(y, "y");
            const auto r = matrix<T>(rates, "rates");
            const an::DecodingParams params{gridsize, quantile, extent_of(extent),
                                            an::parse_decoding_templates(templates)};
            an::DecodingResult d;
            interruptible([&](const std::atomic<bool>&) { d = an::decoding_error<T>(xs, ys, r, params); });
            return decoding_dict(d);
        },
        pyb::arg("x"), pyb::arg("y"), values_arg("rates"), pyb::arg("gridsize"), pyb::arg("extent"),
        pyb::arg("quantile"), pyb::arg("templates"));
    a.def(
        "cell_stats",
        [](const ArrayD& x, const ArrayD& y, const Array<T>& rates, int gridsize, double quantile,
           const MaybeExtent& extent) {
            const auto xs = span1d(x, "x"), ys = span1d(y, "y");
            const auto r = matrix<T>(rates, "rates");
            an::CellStats s;
            interruptible([&](const std::atomic<bool>&) {
                s = an::cell_stats(an::rate_maps<T>(xs, ys, r, {gridsize, quantile, extent_of(extent)}));
            });
            return stats_dict(s);
        },
        pyb::arg("x"), pyb::arg("y"), values_arg("rates"), pyb::arg("gridsize"), pyb::arg("quantile"),
        pyb::arg("extent"));
    a.def(
        "analyze",
        [](const ArrayD& x, const ArrayD& y, const Array<T>& rates, int gridsize, double quantile, double eps,
           int min_samples, double d_th, const MaybeExtent& extent, const std::string& decoding_templates,
           double mi_quantile, int skip_samples, int msai_bins) {
            const auto xs = span1d(x, "x"), ys = span1d(y, "y");
            const auto r = matrix<T>(rates, "rates");
            an::AnalysisParams params;
            params.gridsize = gridsize;
            params.quantile = quantile;
            params.dbscan = {eps, min_samples};
            params.d_th = d_th;
            params.extent = extent_of(extent);
            params.decoding_templates = an::parse_decoding_templates(decoding_templates);
            params.mi_quantile = mi_quantile;
            params.skip_samples = skip_samples;
            params.msai_bins = msai_bins;
            an::TrialMetrics m;
            interruptible([&](const std::atomic<bool>&) { m = an::analyze_trial<T>(xs, ys, r, params); });
            pyb::dict d = trial_analysis_dict(m, "bin_area_m2", decoding_dict(m.decoding));
            return d;
        },
        pyb::arg("x"), pyb::arg("y"), values_arg("rates"), pyb::arg("gridsize"), pyb::arg("quantile"), pyb::arg("eps"),
        pyb::arg("min_samples"), pyb::arg("d_th"), pyb::arg("extent"), pyb::arg("decoding_templates"),
        pyb::arg("mi_quantile"), pyb::arg("skip_samples"), pyb::arg("msai_bins"));
}

// 3-D (flying agents): voxel rate maps and the whole analysis of N × 3 positions.
template <class T>
void bind_voxel_functions(pyb::module_& a) {
    auto values_arg = [](const char* name) {
        auto arg = pyb::arg(name);
        if constexpr (std::is_same_v<T, float>) arg.noconvert();
        return arg;
    };
    a.def(
        "voxel_rate_maps",
        [](const ArrayD& positions, const Array<T>& rates, double voxel, const MaybeBox& volume, double quantile) {
            const auto p = positions3(positions);
            const auto r = matrix<T>(rates, "rates");
            an::RateMaps m;
            {
                pyb::gil_scoped_release release;
                auto grid = std::make_shared<an::VoxelGrid>(an::VoxelGrid::fit(p, voxel, box_of(volume)));
                m = an::rate_maps<T>(grid, p, r, quantile);
            }
            return pyb::make_tuple(numpy_of(m.bins.centers), numpy_of(m.map), numpy_of(m.mean),
                                   numpy_of(m.bins.counts));
        },
        pyb::arg("positions"), values_arg("rates"), pyb::arg("voxel"), pyb::arg("volume"), pyb::arg("quantile"));
    a.def(
        "analyze3d",
        [](const ArrayD& positions, const Array<T>& rates, double voxel, const MaybeBox& volume, double quantile,
           double eps, int min_samples, double d_th, const std::string& decoding_templates) {
            const auto p = positions3(positions);
            const auto r = matrix<T>(rates, "rates");
            an::AnalysisParams params = an::AnalysisParams::defaults(3);
            params.voxel = voxel;
            params.volume = box_of(volume);
            params.quantile = quantile;
            params.dbscan = {eps, min_samples};
            params.d_th = d_th;
            params.decoding_templates = an::parse_decoding_templates(decoding_templates);
            an::TrialMetrics m;
            {
                pyb::gil_scoped_release release;
                m = an::analyze_trial<T>(p, r, params);
            }
            pyb::dict d = trial_analysis_dict(m, "voxel_volume_m3", decoding_dict_3d(m.decoding));
            d["isotropy"] = numpy_of(m.isotropy);
            pyb::dict scalars;
            for (const auto& [name, v] : an::scalar_metrics(m)) scalars[name.c_str()] = v;
            d["metrics"] = scalars;
            return d;
        },
        pyb::arg("positions"), values_arg("rates"), pyb::arg("voxel"), pyb::arg("volume"), pyb::arg("quantile"),
        pyb::arg("eps"), pyb::arg("min_samples"), pyb::arg("d_th"), pyb::arg("decoding_templates"));
}

}  // namespace

void bind_analysis(pyb::module_& m) {
    auto a = m.def_submodule("analysis", "Analysis stage (use bvc3d.analysis)");
    a.def(
        "defaults",
        [](int dims) {
            if (dims != 2 && dims != 3) throw InputError("dims must be 2 or 3, got " + std::to_string(dims));
            const auto p = an::AnalysisParams::defaults(dims);
            pyb::dict d;
            for (const auto& f : an::AnalysisParams::table().fields()) d[f.key.c_str()] = from_value(f.get(p));
            d["voxel"] = p.voxel;  // not a key of the table (trial files of 2-D trials do not record it)
            return d;
        },
        pyb::arg("dims"),
        "The analysis parameters' defaults for positions of `dims` (2 or 3) coordinates, by the keys of the C++ "
        "table (AnalysisParams::table()), and the voxel side: what bvc3d.analysis takes as its defaults");
    a.attr("decoding_templates") = an::AnalysisParams::table().find("decoding_templates")->choices;
    bind_sample_functions<float>(a);  // first: taken only for float32 input, without conversion
    bind_sample_functions<double>(a);
    bind_voxel_functions<float>(a);
    bind_voxel_functions<double>(a);

    a.def(
        "dbscan_labels",
        [](const ArrayD& points, double eps, int min_samples) {
            const auto p = centers_of(points);
            std::vector<int> labels;
            {
                pyb::gil_scoped_release release;
                labels = an::dbscan_labels(p, {eps, min_samples});
            }
            return numpy_of(labels);
        },
        pyb::arg("points"), pyb::arg("eps"), pyb::arg("min_samples"));
    a.def(
        "isotropy",
        [](const ArrayD& centers, const ArrayD& maps, const std::vector<int>& modality, double eps, int min_samples) {
            const auto c = centers_of(centers);
            const auto mp = matrix<double>(maps, "maps");
            std::vector<double> iso;
            {
                pyb::gil_scoped_release release;
                iso = an::field_isotropy(c, mp, modality, {eps, min_samples});
            }
            return numpy_of(iso);
        },
        pyb::arg("centers"), pyb::arg("maps"), pyb::arg("modality"), pyb::arg("eps"), pyb::arg("min_samples"));

    a.def(
        "dbscan_cluster_count",
        [](const ArrayD& points, double eps, int min_samples) {
            const auto p = centers_of(points);
            return interruptible([&](const std::atomic<bool>&) {
                return an::dbscan_cluster_count(p, {eps, min_samples});
            });
        },
        pyb::arg("points"), pyb::arg("eps"), pyb::arg("min_samples"));
    a.def(
        "radius_neighbors",
        [](const ArrayD& points, double eps) {
            const auto p = centers_of(points);
            an::Neighborhoods nb;
            interruptible([&](const std::atomic<bool>&) { nb = an::sklearn_radius_neighbors(p, eps); });
            return pyb::make_tuple(numpy_of(nb.offsets), numpy_of(nb.indices));
        },
        pyb::arg("points"), pyb::arg("eps"));
    a.def(
        "modality",
        [](const ArrayD& centers, const ArrayD& maps, double eps, int min_samples) {
            const auto c = centers_of(centers);
            const auto mp = matrix<double>(maps, "maps");
            std::vector<int> mi;
            interruptible([&](const std::atomic<bool>&) { mi = an::modality(c, mp, {eps, min_samples}); });
            return numpy_of(mi);
        },
        pyb::arg("centers"), pyb::arg("maps"), pyb::arg("eps"), pyb::arg("min_samples"));
    a.def(
        "modality_summary",
        [](const pyb::array_t<int, pyb::array::c_style | pyb::array::forcecast>& counts) {
            if (counts.ndim() != 1) throw InputError("counts must be 1-D");
            return summary_dict(an::summarize_modality({counts.data(), static_cast<std::size_t>(counts.shape(0))}));
        },
        pyb::arg("counts"));
    a.def(
        "percentile",
        [](const ArrayD& values, double percent) {
            std::vector<double> v(values.data(), values.data() + values.size());
            return an::percentile_linear(v, percent);
        },
        pyb::arg("values"), pyb::arg("percent"), "numpy.percentile(values, percent), linear (for tests)");
    a.def(
        "aliasing",
        [](const ArrayD& centers, const ArrayD& maps, double d_th) {
            const auto c = centers_of(centers);
            const auto mp = matrix<double>(maps, "maps");
            an::AliasingResult r;
            interruptible([&](const std::atomic<bool>&) { r = an::spatial_aliasing(c, mp, d_th); });
            return pyb::make_tuple(to_numpy(r.sai.data(), {r.sai.size()}), r.msai);
        },
        pyb::arg("centers"), pyb::arg("maps"), pyb::arg("d_th"));
}

}  // namespace bvc3d::py

// BoundaryVectorLayer, PlaceCellNetwork and the model presets.
#include "bindings.hpp"

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/experiment/experiment.hpp"
#include "bvc3d/experiment/model_spec.hpp"
#include "bvc3d/experiment/trial_runner.hpp"
#include "bvc3d/recorder/trial_file.hpp"

namespace bvc3d::py {

namespace {

// An (N, 3) float64 array of range, azimuth, elevation viewed as LidarReturns (no copy).
std::span<const LidarReturn> returns_view(const ArrayD& a) {
    if (a.ndim() != 2 || a.shape(1) != 3)
        throw InputError("returns must be an (N, 3) array of range, azimuth, elevation");
    return {reinterpret_cast<const LidarReturn*>(a.data()), static_cast<std::size_t>(a.shape(0))};
}

pyb::array_t<double> compute(const BoundaryVectorLayer& layer, const ArrayD& returns, bool normalised) {
    const auto view = returns_view(returns);
    std::vector<double> out(layer.n_cells());
    {
        pyb::gil_scoped_release release;
        normalised ? layer.rates(view, out) : layer.raw(view, out);
    }
    return to_numpy(out.data(), {static_cast<pyb::ssize_t>(out.size())});
}

}  // namespace

void bind_model(pyb::module_& m) {
    pyb::class_<BoundaryVectorLayer>(m, "BoundaryVectorLayer", R"doc(
Boundary vector cells tuned to distance, allocentric azimuth and elevation (SPEC §5).
Cell i = (l, k, m) sits at index (l·n_dir + k)·n_per_axis + m. elevations=None or [] is the 2-D model.)doc")
        .def(pyb::init([](std::optional<std::vector<double>> elevations, int n_dir, int n_per_axis, double max_dist,
                          double sigma_r, double sigma_theta, double sigma_phi, const std::string& normalization,
                          double norm_constant, const std::string& reading) {
                 BvcParams p;
                 p.elevations = elevations.value_or(std::vector<double>{});
                 p.n_dir = n_dir;
                 p.n_per_axis = n_per_axis;
                 p.max_dist = max_dist;
                 p.sigma_r = sigma_r;
                 p.sigma_theta = sigma_theta;
                 p.sigma_phi = sigma_phi;
                 p.normalization = parse_bvc_normalization(normalization);
                 p.norm_constant = norm_constant;
                 p.reading = parse_bvc_reading(reading);
                 return BoundaryVectorLayer(p);
             }),
             pyb::arg("elevations") = std::vector<double>{0.0, 0.2}, pyb::arg("n_dir") = 8, pyb::arg("n_per_axis") = 60,
             pyb::arg("max_dist") = 12.0, pyb::arg("sigma_r") = 0.75, pyb::arg("sigma_theta") = 0.1,
             pyb::arg("sigma_phi") = 0.01, pyb::arg("normalization") = "per_step_max", pyb::arg("norm_constant") = 1.0,
             pyb::arg("reading") = "gaussian")
        .def_static(
            "preset", [](const std::string& name) { return BoundaryVectorLayer(config::resolve_model(name).bvc); },
            pyb::arg("name"), "The BVC layer of a model preset (2d, 3d-0.1, 3d-0.2, 3d-3l, 2d-8beam) or model YAML")
        .def("rates", [](const BoundaryVectorLayer& l, const ArrayD& r) { return compute(l, r, true); },
             pyb::arg("returns"), "Normalised rates (n_cells,) for an (N, 3) array of returns")
        .def("raw", [](const BoundaryVectorLayer& l, const ArrayD& r) { return compute(l, r, false); },
             pyb::arg("returns"), "Unnormalised sums (n_cells,)")
        .def_property_readonly("n_cells", &BoundaryVectorLayer::n_cells)
        .def_property_readonly("elevations", [](const BoundaryVectorLayer& l) { return l.params().elevations; })
        .def_property_readonly("n_dir", [](const BoundaryVectorLayer& l) { return l.params().n_dir; })
        .def_property_readonly("n_per_axis", [](const BoundaryVectorLayer& l) { return l.params().n_per_axis; })
        .def_property_readonly(
            "preferred",
            [](const BoundaryVectorLayer& l) {
                const auto& p = l.params();
                const auto n = static_cast<pyb::ssize_t>(l.n_cells());
                pyb::array_t<double> el(n), az(n), d(n);
                for (pyb::ssize_t i = 0; i < n; ++i) {
                    const int dist = static_cast<int>(i % p.n_per_axis);
                    const int dir = static_cast<int>(i / p.n_per_axis % p.n_dir);
                    const int layer = static_cast<int>(i / (p.n_per_axis * p.n_dir));
                    el.mutable_at(i) = p.elevations.empty() ? 0.0 : p.elevations[layer];
                    az.mutable_at(i) = dir * 2 * 3.14159265358979323846 / p.n_dir;
                    d.mutable_at(i) = dist * p.spacing();
                }
                pyb::dict out;
                out["elevation"] = el;
                out["azimuth"] = az;
                out["distance"] = d;
                return out;
            },
            "dict of arrays: each cell's preferred elevation, azimuth and distance");

    pyb::class_<PlaceCellNetwork>(m, "PlaceCellNetwork", "Place cells driven by BVCs, with Oja learning (SPEC §6)")
        .def(pyb::init([](int n_bvc, int n_place, std::uint64_t seed, double p_connect, double dt_over_tau,
                          double gamma_pb, double gamma_pp, double gain, double eta, double alpha_pb) {
                 PlaceParams p;
                 p.n_place = n_place;
                 p.p_connect = p_connect;
                 p.dt_over_tau = dt_over_tau;
                 p.gamma_pb = gamma_pb;
                 p.gamma_pp = gamma_pp;
                 p.gain = gain;
                 p.eta = eta;
                 p.alpha_pb = alpha_pb;
                 return PlaceCellNetwork(n_bvc, p, seed);
             }),
             pyb::arg("n_bvc"), pyb::arg("n_place") = 250, pyb::arg("seed") = 0, pyb::arg("p_connect") = 0.25,
             pyb::arg("dt_over_tau") = 0.5, pyb::arg("gamma_pb") = 0.3, pyb::arg("gamma_pp") = 0.5,
             pyb::arg("gain") = 1.0, pyb::arg("eta") = 0.096, pyb::arg("alpha_pb") = 0.70710678118654752)
        .def(
            "step",
            [](PlaceCellNetwork& net, const ArrayD& bvc_rates, bool learn) {
                if (bvc_rates.ndim() != 1) throw InputError("bvc_rates must be a 1-D array");
                const std::span<const double> in(bvc_rates.data(), static_cast<std::size_t>(bvc_rates.shape(0)));
                const auto out = net.step(in, learn);
                return to_numpy(out.data(), {static_cast<pyb::ssize_t>(out.size())}).attr("astype")("float64");
            },
            pyb::arg("bvc_rates"), pyb::arg("learn") = true, "One model step; returns the (n_place,) rates")
        .def_property(
            "weights",
            [](const PlaceCellNetwork& net) {
                const auto w = net.weights();
                return to_numpy(w.data(), {net.n_place(), net.n_bvc()});
            },
            [](PlaceCellNetwork& net, const pyb::array_t<float, pyb::array::c_style | pyb::array::forcecast>& w) {
                if (w.ndim() != 2 || w.shape(0) != net.n_place() || w.shape(1) != net.n_bvc())
                    throw InputError("weights must have shape (" + std::to_string(net.n_place()) + ", " +
                                     std::to_string(net.n_bvc()) + ")");
                net.set_weights({w.data(), static_cast<std::size_t>(w.size())});
            },
            "(n_place, n_bvc) float32 weights; assign to restore a trained network")
        .def_property_readonly("rates", [](const PlaceCellNetwork& n) {
            return to_numpy(n.rates().data(), {static_cast<pyb::ssize_t>(n.rates().size())});
        })
        .def_property_readonly("membrane", [](const PlaceCellNetwork& n) {
            return to_numpy(n.membrane().data(), {static_cast<pyb::ssize_t>(n.membrane().size())});
        })
        .def_property_readonly("n_place", &PlaceCellNetwork::n_place)
        .def_property_readonly("n_bvc", &PlaceCellNetwork::n_bvc)
        .def("reset", &PlaceCellNetwork::reset, "Membrane and rates back to zero; weights kept");

    m.def(
        "run_trial",
        [](const std::string& model, const std::string& world, std::optional<double> tilt_deg, std::uint64_t seed,
           double explore_hours, double sample_hours, const std::string& protocol, bool record_bvc) {
            TrialConfig t;
            t.model = config::resolve_model(model);
            t.world = WorldSpec{world, tilt_deg, "+x+y"};
            t.seed = seed;
            t.protocol.kind = parse_protocol(protocol);
            t.protocol.explore_hours = explore_hours;
            t.protocol.sample_hours = sample_hours;
            t.protocol.record_bvc = record_bvc;
            t.validate();
            const WorldDescription w = t.world.resolve();
            GroupResult r;
            analysis::TrialMetrics metrics;
            {
                pyb::gil_scoped_release release;
                r = run_trial_group({t});
                metrics = analyze(t, w, r.x, r.y, r.models[0].rates, r.models[0].n_place);
            }
            const auto n = static_cast<pyb::ssize_t>(r.t.size());
            const auto& rec = r.models[0];
            pyb::dict out;
            out["t"] = to_numpy(r.t.data(), {n});
            out["x"] = to_numpy(r.x.data(), {n});
            out["y"] = to_numpy(r.y.data(), {n});
            out["heading"] = to_numpy(r.heading.data(), {n});
            out["rates"] = to_numpy(rec.rates.data(), {n, rec.n_place});
            if (record_bvc) out["bvc_rates"] = to_numpy(rec.bvc.data(), {n, rec.n_bvc});
            out["weights"] = to_numpy(rec.weights.data(), {rec.n_place, rec.n_bvc});
            pyb::dict scalars;
            for (const auto& [name, v] : scalar_metrics(metrics)) scalars[name.c_str()] = v;
            out["metrics"] = scalars;
            out["name"] = t.name();
            return out;
        },
        pyb::arg("model") = "3d-0.2", pyb::arg("world") = "cross", pyb::arg("tilt_deg") = pyb::none(),
        pyb::arg("seed") = 0, pyb::arg("explore_hours") = 4.0, pyb::arg("sample_hours") = 4.0,
        pyb::arg("protocol") = "explore_then_sample", pyb::arg("record_bvc") = false,
        R"doc(One trial (SPEC §7) at full speed, as `bvc3d run` does it, returned as numpy arrays: t, x, y,
heading (samples,), rates (samples, n_place) float32, weights (n_place, n_bvc), bvc_rates if recorded,
and metrics (dict of SPEC §8's scalar metrics). model: a preset or model YAML; world: a preset or world
YAML; tilt_deg: for world="cross".)doc");

    m.def("model_presets", &model_preset_names, "Names of the model presets");
    m.def(
        "model_sensor", [](const std::string& name) { return config::resolve_model(name).sensor; }, pyb::arg("model"),
        "The Sensor a model preset (or model YAML) reads");
}

}  // namespace bvc3d::py

// BoundaryVectorLayer, PlaceCellNetwork and the model presets.
#include "bindings.hpp"

#include "bvc3d/bvc/boundary_vector_layer.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/place/place_cell_network.hpp"

namespace bvc3d::py {

namespace {

// An (N, 3) float64 array of range, azimuth, elevation viewed as LidarReturns (no copy).
std::span<const LidarReturn> returns_view(const ArrayD& a) {
    if (a.ndim() != 2 || a.shape(1) != 3)
        throw InputError("returns must be an (N, 3) array of range, azimuth, elevation");
    return {reinterpret_cast<const LidarReturn*>(a.data()), static_cast<std::size_t>(a.shape(0))};
}

pyb::array_t<double> compute(const BoundaryVectorLayer& layer, const pyb::handle& obj, bool normalized) {
    const ArrayD returns = real_array(obj, "returns");
    const auto view = returns_view(returns);
    std::vector<double> out(layer.n_cells());
    {
        pyb::gil_scoped_release release;
        normalized ? layer.rates(view, out) : layer.raw(view, out);
    }
    return to_numpy(out.data(), {static_cast<pyb::ssize_t>(out.size())});
}

// Each cell's preferred elevation, azimuth and distance.
pyb::dict preferred(const BoundaryVectorLayer& l) {
    const auto& p = l.params();
    const auto n = static_cast<pyb::ssize_t>(l.n_cells());
    pyb::array_t<double> el(n), az(n), d(n);
    for (pyb::ssize_t i = 0; i < n; ++i) {
        const int dist = static_cast<int>(i % p.n_per_axis);
        const int dir = static_cast<int>(i / p.n_per_axis % p.n_dir);
        const int layer = static_cast<int>(i / (p.n_per_axis * p.n_dir));
        el.mutable_at(i) = p.elevations.empty() ? 0.0 : p.elevations[layer];
        az.mutable_at(i) = dir * two_pi / p.n_dir;
        d.mutable_at(i) = dist * p.spacing();
    }
    pyb::dict out;
    out["elevation"] = el;
    out["azimuth"] = az;
    out["distance"] = d;
    return out;
}

void bind_layer(pyb::module_& m) {
    auto cls = pyb::class_<BoundaryVectorLayer>(m, "BoundaryVectorLayer",
                                                (R"doc(
Boundary vector cells tuned to distance, allocentric azimuth and elevation (docs/model-reference.md).
Cell i = (l, k, m) sits at index (l·n_dir + k)·n_per_axis + m. elevations=None or [] is the 2-D model.
Keyword arguments and their defaults (the `3d-0.2` model's layer):
)doc" + describe(BvcParams::table(), BvcParams{}))
                                                    .c_str());
    cls.def(pyb::init([](const pyb::args& args, const pyb::kwargs& kwargs) {
           BvcParams p;
           apply_args(p, BvcParams::table(), args, kwargs);
           return BoundaryVectorLayer(p);
       }))
        .def_static(
            "preset", [](const std::string& name) { return BoundaryVectorLayer(config::resolve_model(name).bvc); },
            pyb::arg("name"), "The BVC layer of a model preset (2d, 3d-0.1, 3d-0.2, 3d-3l, 2d-8beam) or model YAML")
        .def(
            "rates", [](const BoundaryVectorLayer& l, const pyb::object& r) { return compute(l, r, true); },
            pyb::arg("returns"), "Normalized rates (n_cells,) for an (N, 3) array of returns")
        .def(
            "raw", [](const BoundaryVectorLayer& l, const pyb::object& r) { return compute(l, r, false); },
            pyb::arg("returns"), "Unnormalized sums (n_cells,)")
        .def_property_readonly("n_cells", &BoundaryVectorLayer::n_cells)
        .def_property_readonly("preferred", &preferred,
                               "dict of arrays: each cell's preferred elevation, azimuth and distance");
    for (const auto& f : BvcParams::table().fields())
        cls.def_property_readonly(
            f.key.c_str(), [get = f.get](const BoundaryVectorLayer& l) { return from_value(get(l.params())); },
            f.doc.c_str());
}

void bind_network(pyb::module_& m) {
    auto cls = pyb::class_<PlaceCellNetwork>(m, "PlaceCellNetwork",
                                             (R"doc(
Place cells driven by BVCs, with Oja learning (docs/model-reference.md#place-cell-network), and optionally by grid
cells too (n_grid > 0, grid_influence g: docs/model-reference.md#place-cells-fed-by-grid-cells).
PlaceCellNetwork(n_bvc, seed=0, n_grid=0, **params), positionally in that order and then the params'; params and their
defaults:
)doc" + describe(PlaceParams::table(), PlaceParams{}))
                                                 .c_str());
    cls.def(pyb::init([](const pyb::args& args, const pyb::kwargs& kwargs) {
           std::vector<std::string> names{"n_bvc", "seed", "n_grid"};
           const auto params = keys_of(PlaceParams::table());
           names.insert(names.end(), params.begin(), params.end());
           pyb::kwargs given = named_arguments("PlaceCellNetwork", args, kwargs, names, {"n_bvc"});
           const int n_bvc = count_of(given.attr("pop")("n_bvc"), "n_bvc");
           const auto seed = seed_of(given.attr("pop")("seed", 0), "seed");
           const int n_grid = count_of(given.attr("pop")("n_grid", 0), "n_grid");
           PlaceParams p;
           apply_kwargs(p, PlaceParams::table(), given);
           return PlaceCellNetwork(n_bvc, p, seed, n_grid);
       }))
        .def(
            "step",
            [](PlaceCellNetwork& net, const pyb::object& obj, const pyb::object& learn_obj,
               const pyb::object& grid_obj) {
                const bool learn = flag_of(learn_obj, "learn");
                const ArrayD bvc_rates = real_array(obj, "bvc_rates");
                if (bvc_rates.ndim() != 1) throw InputError("bvc_rates must be a 1-D array");
                const std::span<const double> in(bvc_rates.data(), static_cast<std::size_t>(bvc_rates.shape(0)));
                if (grid_obj.is_none() && net.n_grid() > 0)
                    throw InputError("grid_rates: this network reads " + std::to_string(net.n_grid()) + " grid cells");
                const ArrayD grid_rates = grid_obj.is_none() ? ArrayD() : real_array(grid_obj, "grid_rates");
                if (!grid_obj.is_none() && grid_rates.ndim() != 1) throw InputError("grid_rates must be a 1-D array");
                const std::span<const double> grid(
                    grid_rates.data(), grid_obj.is_none() ? 0 : static_cast<std::size_t>(grid_rates.shape(0)));
                const auto out = net.step(in, grid, learn);
                return to_numpy(out.data(), {static_cast<pyb::ssize_t>(out.size())}).attr("astype")("float64");
            },
            pyb::arg("bvc_rates"), pyb::arg("learn") = true, pyb::arg("grid_rates") = pyb::none(),
            "One model step; returns the (n_place,) rates. grid_rates: (n_grid,), when the network reads grid cells")
        .def_property_readonly(
            "grid_mask",
            [](const PlaceCellNetwork& net) {
                const auto w = net.grid_mask();
                return to_numpy(w.data(), {net.n_place(), net.n_grid()});
            },
            "(n_place, n_grid) float32 mask W_g (0 or 1), fixed, drawn from the seed")
        .def_property_readonly("n_grid", &PlaceCellNetwork::n_grid)
        .def_property(
            "weights",
            [](const PlaceCellNetwork& net) {
                const auto w = net.weights();
                return to_numpy(w.data(), {net.n_place(), net.n_bvc()});
            },
            [](PlaceCellNetwork& net, const pyb::object& obj) {
                const auto w = real_array_f32(obj, "weights");
                if (w.ndim() != 2 || w.shape(0) != net.n_place() || w.shape(1) != net.n_bvc())
                    throw InputError("weights must have shape (" + std::to_string(net.n_place()) + ", " +
                                     std::to_string(net.n_bvc()) + ")");
                net.set_weights({w.data(), static_cast<std::size_t>(w.size())});
            },
            "(n_place, n_bvc) float32 weights; assign to restore a trained network")
        .def_property_readonly("rates",
                               [](const PlaceCellNetwork& n) {
                                   return to_numpy(n.rates().data(), {static_cast<pyb::ssize_t>(n.rates().size())});
                               })
        .def_property_readonly("membrane",
                               [](const PlaceCellNetwork& n) {
                                   return to_numpy(n.membrane().data(),
                                                   {static_cast<pyb::ssize_t>(n.membrane().size())});
                               })
        .def_property_readonly("n_bvc", &PlaceCellNetwork::n_bvc)
        .def("reset", &PlaceCellNetwork::reset, "Membrane and rates back to zero; weights kept");
    for (const auto& f : PlaceParams::table().fields())
        cls.def_property_readonly(
            f.key.c_str(), [get = f.get](const PlaceCellNetwork& n) { return from_value(get(n.params())); },
            f.doc.c_str());
}

}  // namespace

void bind_model(pyb::module_& m) {
    bind_layer(m);
    bind_network(m);
    m.def("model_presets", &model_preset_names, "Names of the model presets");
    m.def(
        "model_sensor", [](const std::string& name) { return config::resolve_model(name).sensor; }, pyb::arg("model"),
        "The Sensor a model preset (or model YAML) reads");
}

}  // namespace bvc3d::py

// GrowingPlaceCells (issue 29): a place-cell network that recruits cells where none fires, stepped by hand.
#include "bindings.hpp"

#include "bvc3d/population/growing_place_cells.hpp"

namespace bvc3d::py {

namespace {

template <class T>
pyb::array_t<double> as_float64(std::span<const T> v) {
    std::vector<double> out(v.begin(), v.end());
    return to_numpy(out.data(), {static_cast<pyb::ssize_t>(out.size())});
}

std::vector<std::string> keys(const auto& table) {
    std::vector<std::string> k;
    for (const auto& f : table.fields()) k.push_back(f.key);
    return k;
}

}  // namespace

void bind_growing(pyb::module_& m) {
    using G = GrowingPlaceCells;
    auto cls = pyb::class_<G>(
        m, "GrowingPlaceCells",
        (R"doc(
A growing place-cell network (docs/model-reference.md#growing-place-cells): the paper's network of its recruited cells
(§6, Oja), which recruits a cell on every sample_every-th learning step where no cell's rate reaches threshold, its
weights (p_connect·n_bvc)·v_b/Σv_b, up to budget cells. GrowingPlaceCells(n_bvc, seed=0, **params), positionally
in that order and then the parameters below, growing ones first. step(bvc_rates, learn=True) takes (n_bvc,) rates and
gives the budget's (budget,) rates, cells not recruited 0.
Growing parameters and their defaults:
)doc" + describe(GrowingParams::table(), GrowingParams{}) +
         "Place-cell dynamics and their defaults (the place cells' n_place aside: the cells are budget and "
         "n_initial):\n" +
         describe(PlaceParams::table(), PlaceParams{}, {"n_place"}))
            .c_str());
    cls.def(pyb::init([](const pyb::args& args, const pyb::kwargs& kwargs) {
           if (kwargs.contains("n_place"))
               throw InputError("growing place cells: n_place is not a parameter (the cells are budget and n_initial)");
           std::vector<std::string> names{"n_bvc", "seed"};
           for (const auto& k : keys_of(GrowingParams::table())) names.push_back(k);
           for (const auto& k : keys_of(PlaceParams::table(), {"n_place"})) names.push_back(k);
           pyb::kwargs given = named_arguments("GrowingPlaceCells", args, kwargs, names, {"n_bvc"});
           const int n_bvc = count_of(given.attr("pop")("n_bvc"), "n_bvc");
           const auto seed = seed_of(given.attr("pop")("seed", 0), "seed");
           GrowingParams g;
           PlaceParams p;
           apply_kwargs(g, GrowingParams::table(), given, keys(PlaceParams::table()));
           apply_kwargs(p, PlaceParams::table(), given, keys(GrowingParams::table()));
           return std::make_unique<G>(n_bvc, p, g, seed);
       }))
        .def(
            "step",
            [](G& net, const pyb::object& obj, const pyb::object& learn_obj) {
                const bool learn = flag_of(learn_obj, "learn");
                const ArrayD b = real_array(obj, "bvc_rates");
                if (b.ndim() != 1) throw InputError("bvc_rates must be a 1-D array");
                return as_float64(net.step({b.data(), static_cast<std::size_t>(b.shape(0))}, learn));
            },
            pyb::arg("bvc_rates"), pyb::arg("learn") = true,
            "One model step (recruiting after it if it is a sampled learning step); returns the (budget,) rates")
        .def("reset", &G::reset, "Membrane and rates back to 0; weights and cells kept")
        .def_property_readonly(
            "weights",
            [](const G& net) {
                const auto w = net.weights();
                return to_numpy(w.data(), {net.n_cells(), net.n_bvc()});
            },
            "(n_cells, n_bvc) float32 weights of the recruited cells")
        .def_property_readonly(
            "recruited_at",
            [](const G& net) {
                const auto& a = net.recruited_at();
                return to_numpy(a.data(), {static_cast<pyb::ssize_t>(a.size())});
            },
            "(n_cells,) the learning step (1, 2, ...) at which each cell was recruited; 0 for the initial ones")
        .def_property_readonly(
            "rates", [](const G& net) { return as_float64(net.rates()); }, "(budget,) rates of the last step")
        .def_property_readonly("n_cells", &G::n_cells, "cells recruited so far, with the initial ones")
        .def_property_readonly("n_bvc", &G::n_bvc)
        .def_property_readonly("learning_steps", &G::learning_steps, "learning steps taken");
    for (const auto& f : GrowingParams::table().fields())
        cls.def_property_readonly(
            f.key.c_str(), [get = f.get](const G& c) { return from_value(get(c.params())); }, f.doc.c_str());
    for (const auto& f : PlaceParams::table().fields())
        if (f.key != "n_place")
            cls.def_property_readonly(
                f.key.c_str(), [get = f.get](const G& c) { return from_value(get(c.place_params())); }, f.doc.c_str());
}

}  // namespace bvc3d::py

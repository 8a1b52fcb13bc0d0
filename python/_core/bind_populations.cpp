// HeadDirectionCells and GridCells (issue 29): populations a neuroscientist can step by hand, numpy in, numpy out.
#include "bindings.hpp"

#include "bvc3d/population/grid_cells.hpp"
#include "bvc3d/population/head_direction_cells.hpp"

namespace bvc3d::py {

namespace {

// Rows of `width` values of `a` (a 1-D array of `width` values is one row); `rows` gets the count, `single` whether
// the input was one row without a leading axis.
ArrayD rows_of(const pyb::handle& obj, const std::string& name, pyb::ssize_t width, pyb::ssize_t& rows, bool& single) {
    ArrayD a = real_array(obj, name);
    const std::string want = width == 1 ? "a number or an (M,) array" : "an (M, " + std::to_string(width) + ") array";
    if (width == 1 && a.ndim() <= 1) {
        single = a.ndim() == 0;
        rows = a.ndim() == 0 ? 1 : a.shape(0);
    } else if (a.ndim() == 2 && a.shape(1) == width) {
        single = false;
        rows = a.shape(0);
    } else if (a.ndim() == 1 && a.shape(0) == width) {
        single = true;
        rows = 1;
    } else {
        throw InputError(name + " must be " + want);
    }
    for (pyb::ssize_t i = 0; i < a.size(); ++i)
        if (!std::isfinite(a.data()[i])) throw InputError(name + " holds a value that is not finite");
    return a;
}

pyb::array_t<double> result(const std::vector<double>& v, pyb::ssize_t rows, pyb::ssize_t n, bool single) {
    return single ? to_numpy(v.data(), {n}) : to_numpy(v.data(), {rows, n});
}

void bind_head_direction(pyb::module_& m) {
    auto cls = pyb::class_<HeadDirectionCells>(m, "HeadDirectionCells",
                                               (R"doc(
Head-direction cells (docs/model-reference.md#head-direction-cells). planar: v_k = cos(θ − 2πk/n) for heading θ;
spherical: v_k = u_k · w/|w| for the 3-D direction w, u_k the 20 face normals of an icosahedron (`preferred`).
Keyword arguments and their defaults:
)doc" + describe(HeadDirectionParams::table(), HeadDirectionParams{}))
                                                   .c_str());
    cls.def(pyb::init([](const pyb::args& args, const pyb::kwargs& kwargs) {
           HeadDirectionParams p;
           apply_args(p, HeadDirectionParams::table(), args, kwargs);
           // The spherical cells are the icosahedron's 20, whatever n says: an n other than that is a mistake.
           const bool n_given = args.size() > 0 || kwargs.contains("n");
           if (p.space == HdSpace::spherical && n_given && p.n != 20)
               throw InputError("head-direction cells: n = " + std::to_string(p.n) +
                                " is the planar cells' count; the spherical cells are the icosahedron's 20");
           return HeadDirectionCells(p);
       }))
        .def(
            "rates",
            [](const HeadDirectionCells& cells, const pyb::object& obj) {
                const bool planar = cells.params().space == HdSpace::planar;
                pyb::ssize_t rows = 0;
                bool single = false;
                const ArrayD a = rows_of(obj, planar ? "heading" : "direction", planar ? 1 : 3, rows, single);
                const auto n = static_cast<std::size_t>(cells.size());
                std::vector<double> out(static_cast<std::size_t>(rows) * n);
                for (pyb::ssize_t i = 0; i < rows; ++i) {
                    const std::span<double> row(out.data() + i * n, n);
                    if (planar) {
                        hd::planar_rates(a.data()[i], row);
                        continue;
                    }
                    const Vec3 w(a.data()[3 * i], a.data()[3 * i + 1], a.data()[3 * i + 2]);
                    if (w.norm() == 0.0) throw InputError("direction " + std::to_string(i) + " has length 0");
                    hd::spherical_rates(w, row);
                }
                return result(out, rows, static_cast<pyb::ssize_t>(n), single);
            },
            pyb::arg("heading"),
            "Rates (M, n) for headings (M,) in rad (planar) or directions (M, 3) (spherical); one input, one row")
        .def_property_readonly(
            "preferred",
            [](const HeadDirectionCells& cells) {
                const auto n = static_cast<pyb::ssize_t>(cells.size());
                if (cells.params().space == HdSpace::planar) {
                    std::vector<double> h(static_cast<std::size_t>(n));
                    for (int k = 0; k < n; ++k) h[k] = hd::preferred_heading(k, static_cast<int>(n));
                    return to_numpy(h.data(), {n});
                }
                std::vector<double> u;
                for (const auto& f : hd::icosahedron_faces()) u.insert(u.end(), {f.x(), f.y(), f.z()});
                return to_numpy(u.data(), {n, 3});
            },
            "Preferred headings (n,) (planar) or unit directions (20, 3) (spherical)")
        .def_property_readonly("n_cells", &HeadDirectionCells::size);
    for (const auto& f : HeadDirectionParams::table().fields())
        if (f.key != "n")
            cls.def_property_readonly(
                f.key.c_str(), [get = f.get](const HeadDirectionCells& c) { return from_value(get(c.params())); },
                f.doc.c_str());
    cls.def_property_readonly("n", &HeadDirectionCells::size, "cells: n planar ones, or the 20 spherical ones");
}

void bind_grid(pyb::module_& m) {
    auto cls = pyb::class_<GridCells>(m, "GridCells",
                                      (R"doc(
Grid cells, the sum of three cosines (docs/model-reference.md#grid-cells). GridCells(spacing=4, orientation=0,
n_orientations=8, n=800, input='pose', path_noise=0.01, seed=0), positionally in that order: cell c has orientation
α + (c mod n_orientations)·2π/n_orientations and a phase spread over the lattice's unit cell (scrambled Sobol, from
the seed). rates(xy) takes (M, 2) positions and gives (M, n) rates in [0, 1]; with input='path' the rows are
successive model steps, and the cells read the position integrated along them from the first, each step's
displacement with Gaussian noise of sd path_noise per axis (integrate(xy) gives that estimate), as in a trial.
Keyword arguments and their defaults:
)doc" + describe(GridParams::table(), GridParams{}) +
                                       "  seed=0  the phases' and the path noise's seed\n")
                                          .c_str());
    cls.def(pyb::init([](const pyb::args& args, const pyb::kwargs& kwargs) {
           auto names = keys_of(GridParams::table());
           names.push_back("seed");
           pyb::kwargs given = named_arguments("GridCells", args, kwargs, names);
           const auto seed = seed_of(given.attr("pop")("seed", 0), "seed");
           GridParams p;
           apply_kwargs(p, GridParams::table(), given);
           return GridCells(p, seed);
       }))
        .def(
            "rates",
            [](const GridCells& cells, const pyb::object& obj) {
                pyb::ssize_t rows = 0;
                bool single = false;
                const ArrayD a = rows_of(obj, "xy", 2, rows, single);
                const auto n = cells.size();
                std::vector<double> out(static_cast<std::size_t>(rows) * n);
                {
                    pyb::gil_scoped_release release;
                    GridCells path = cells;  // a fresh estimate along this path (the object's own is untouched)
                    for (pyb::ssize_t i = 0; i < rows; ++i) {
                        const auto [x, y] =
                            path.read_position(a.data()[2 * i], a.data()[2 * i + 1], static_cast<std::uint64_t>(i));
                        cells.rates(x, y, {out.data() + i * n, n});
                    }
                }
                return result(out, rows, static_cast<pyb::ssize_t>(n), single);
            },
            pyb::arg("xy"),
            "Rates (M, n) at positions (M, 2), m (one position (2,) gives (n,)); input='path': of the position "
            "integrated along the rows")
        .def(
            "integrate",
            [](const GridCells& cells, const pyb::object& obj) {
                pyb::ssize_t rows = 0;
                bool single = false;
                const ArrayD a = rows_of(obj, "xy", 2, rows, single);
                std::vector<double> out(static_cast<std::size_t>(2 * rows));
                GridCells path = cells;
                for (pyb::ssize_t i = 0; i < rows; ++i) {
                    const auto [x, y] =
                        path.read_position(a.data()[2 * i], a.data()[2 * i + 1], static_cast<std::uint64_t>(i));
                    out[static_cast<std::size_t>(2 * i)] = x;
                    out[static_cast<std::size_t>(2 * i + 1)] = y;
                }
                return result(out, rows, 2, single);
            },
            pyb::arg("xy"),
            "The positions (M, 2) the cells read along the path xy (M, 2), one model step a row: xy itself with "
            "input='pose'; with input='path' the estimate integrated from xy[0] with the path noise")
        .def(
            "interference",
            [](const GridCells& cells, const pyb::object& obj) {
                pyb::ssize_t rows = 0;
                bool single = false;
                const ArrayD a = rows_of(obj, "xy", 2, rows, single);
                const auto n = cells.size();
                std::vector<double> out(static_cast<std::size_t>(rows) * n);
                for (pyb::ssize_t i = 0; i < rows; ++i)
                    for (std::size_t c = 0; c < n; ++c)
                        out[i * n + c] = grid::interference(cells.cells()[c], cells.params().spacing, a.data()[2 * i],
                                                            a.data()[2 * i + 1]);
                return result(out, rows, static_cast<pyb::ssize_t>(n), single);
            },
            pyb::arg("xy"), "z ∈ [−0.5, 1] (the sum of cosines / 3) at positions (M, 2)")
        .def_property_readonly(
            "orientations",
            [](const GridCells& cells) {
                std::vector<double> a;
                for (const auto& c : cells.cells()) a.push_back(c.orientation);
                return to_numpy(a.data(), {static_cast<pyb::ssize_t>(a.size())});
            },
            "Each cell's orientation α_c (n,), rad")
        .def_property_readonly(
            "phases",
            [](const GridCells& cells) {
                std::vector<double> t;
                for (const auto& c : cells.cells()) t.insert(t.end(), {c.tx, c.ty});
                return to_numpy(t.data(), {static_cast<pyb::ssize_t>(cells.size()), 2});
            },
            "Each cell's phase t (n, 2), m")
        .def_property_readonly("n_cells", &GridCells::size);
    for (const auto& f : GridParams::table().fields())
        cls.def_property_readonly(
            f.key.c_str(), [get = f.get](const GridCells& c) { return from_value(get(c.params())); }, f.doc.c_str());
}

}  // namespace

void bind_populations(pyb::module_& m) {
    bind_head_direction(m);
    bind_grid(m);
}

}  // namespace bvc3d::py

// bvc3d._core: the compiled half of the Python package. Kept thin: it converts numpy arrays and
// calls the C++ API; everything user-facing is re-exported by bvc3d/__init__.py.
#include "bindings.hpp"

#include "bvc3d/core/error.hpp"

PYBIND11_MODULE(_core, m) {
    m.doc() = "bvc3d compiled core (use the `bvc3d` package)";
    pybind11::register_exception<bvc3d::InputError>(m, "InputError", PyExc_ValueError);
    bvc3d::py::bind_simulator(m);
    bvc3d::py::bind_model(m);
    bvc3d::py::bind_analysis(m);
}

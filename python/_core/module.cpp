// bvc3d._core: the compiled half of the Python package. Kept thin: it converts numpy arrays and
// calls the C++ API; everything user-facing is re-exported by bvc3d/__init__.py.
#include "bindings.hpp"

#include "bvc3d/core/error.hpp"

namespace bvc3d::py {

params::Value to_value(const pyb::handle& obj, params::Kind kind, const std::string& key) {
    using params::Kind;
    const auto wrong = [&](const char* what) { return InputError("'" + key + "' must be " + what); };
    switch (kind) {
        case Kind::real:
            if (pyb::isinstance<pyb::bool_>(obj) || !(pyb::isinstance<pyb::float_>(obj) || pyb::isinstance<pyb::int_>(obj) ||
                                                      pyb::hasattr(obj, "__float__")))
                throw wrong("a number");
            return obj.cast<double>();
        case Kind::integer: {
            if (pyb::isinstance<pyb::bool_>(obj) || !pyb::hasattr(obj, "__index__")) throw wrong("an integer");
            return obj.cast<long long>();
        }
        case Kind::flag:
            if (!pyb::isinstance<pyb::bool_>(obj)) throw wrong("True or False");
            return obj.cast<bool>();
        case Kind::text:
        case Kind::choice:
            if (!pyb::isinstance<pyb::str>(obj)) throw wrong("a string");
            return obj.cast<std::string>();
        case Kind::reals: {
            if (obj.is_none()) return std::vector<double>{};
            if (pyb::isinstance<pyb::str>(obj)) throw wrong("a list of numbers");
            try {
                return obj.cast<std::vector<double>>();
            } catch (const pyb::cast_error&) {
                throw wrong("a list of numbers");
            }
        }
    }
    throw wrong("a supported value");
}

pyb::object from_value(const params::Value& v) {
    return std::visit([](const auto& x) -> pyb::object { return pyb::cast(x); }, v);
}

}  // namespace bvc3d::py

PYBIND11_MODULE(_core, m) {
    m.doc() = "bvc3d compiled core (use the `bvc3d` package)";
    m.attr("__version__") = BVC3D_VERSION;  // the project's version, from CMakeLists.txt
    pybind11::register_exception<bvc3d::InputError>(m, "InputError", PyExc_ValueError);
    bvc3d::py::bind_simulator(m);
    bvc3d::py::bind_model(m);
    bvc3d::py::bind_experiment(m);
    bvc3d::py::bind_analysis(m);
    bvc3d::py::bind_recording(m);
}

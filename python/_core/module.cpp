// bvc3d._core: the compiled half of the Python package. Kept thin: it converts numpy arrays and
// calls the C++ API; everything user-facing is re-exported by bvc3d/__init__.py.
#include "bindings.hpp"

#include <limits>

#include "bvc3d/core/error.hpp"

namespace bvc3d::py {

params::Value to_value(const pyb::handle& obj, params::Kind kind, const std::string& key) {
    using params::Kind;
    const auto wrong = [&](const char* what) { return InputError("'" + key + "' must be " + what); };
    switch (kind) {
        case Kind::real:
            if (pyb::isinstance<pyb::bool_>(obj) ||
                !(pyb::isinstance<pyb::float_>(obj) || pyb::isinstance<pyb::int_>(obj) ||
                  pyb::hasattr(obj, "__float__")))
                throw wrong("a number");
            // numpy scalars: real kinds only (a complex one would lose its imaginary part).
            if (PyComplex_Check(obj.ptr()) ||
                (pyb::hasattr(obj, "dtype") &&
                 std::string("iuf").find(pyb::str(obj.attr("dtype").attr("kind")).cast<std::string>()) ==
                     std::string::npos))
                throw wrong("a real number");
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
                const auto a = real_array(obj, "'" + key + "'");
                if (a.ndim() > 1) throw wrong("a list of numbers (1-D)");
                return std::vector<double>(a.data(), a.data() + a.size());
            } catch (const pyb::error_already_set&) {
                throw wrong("a list of numbers");
            }
        }
    }
    throw wrong("a supported value");
}

namespace {
template <class T>
pyb::array_t<T, pyb::array::c_style | pyb::array::forcecast> real_array_as(const pyb::handle& obj,
                                                                           const std::string& name) {
    pyb::array a;
    try {
        a = pyb::array::ensure(obj);
    } catch (const pyb::error_already_set&) {}
    if (!a) throw InputError(name + " must be an array of numbers");
    const char kind = a.dtype().kind();
    if (kind != 'i' && kind != 'u' && kind != 'f')
        throw InputError(name + " must hold real numbers, got dtype " + pyb::str(a.dtype()).cast<std::string>());
    return pyb::array_t<T, pyb::array::c_style | pyb::array::forcecast>::ensure(a);
}
}  // namespace

ArrayD real_array(const pyb::handle& obj, const std::string& name) { return real_array_as<double>(obj, name); }
pyb::array_t<float, pyb::array::c_style | pyb::array::forcecast> real_array_f32(const pyb::handle& obj,
                                                                                const std::string& name) {
    return real_array_as<float>(obj, name);
}

std::uint64_t seed_of(const pyb::handle& obj, const std::string& name) {
    const std::string range = " must be a whole number from 0 to 18446744073709551615 (2**64 - 1)";
    if (pyb::isinstance<pyb::bool_>(obj) || !pyb::hasattr(obj, "__index__")) throw InputError(name + range);
    const pyb::int_ value(pyb::reinterpret_borrow<pyb::object>(obj).attr("__index__")());
    if (value < pyb::int_(0) || value > pyb::int_(std::numeric_limits<std::uint64_t>::max()))
        throw InputError(name + range + ", got " + std::string(pyb::repr(value)));
    return value.cast<std::uint64_t>();
}

int count_of(const pyb::handle& obj, const std::string& name) {
    const auto v = std::get<long long>(to_value(obj, params::Kind::integer, name));
    if (v < 0 || v > std::numeric_limits<int>::max())
        throw InputError("'" + name + "' must be from 0 to " + std::to_string(std::numeric_limits<int>::max()) +
                         ", got " + std::to_string(v));
    return static_cast<int>(v);
}

bool flag_of(const pyb::handle& obj, const std::string& name) {
    if (pyb::isinstance<pyb::bool_>(obj)) return obj.cast<bool>();
    if (pyb::hasattr(obj, "dtype") && pyb::hasattr(obj, "ndim") && obj.attr("ndim").cast<int>() == 0 &&
        pyb::str(obj.attr("dtype").attr("kind")).cast<std::string>() == "b")
        return obj.attr("item")().cast<bool>();
    throw InputError(name + " must be True or False, not " + type_name(obj));
}

std::string type_name(const pyb::handle& obj) {
    return pyb::str(pyb::type::of(obj).attr("__name__")).cast<std::string>();
}

pyb::kwargs named_arguments(const std::string& what, const pyb::args& args, const pyb::kwargs& kwargs,
                            const std::vector<std::string>& names, const std::vector<std::string>& required) {
    if (args.size() > names.size())
        throw InputError(what + ": too many positional arguments (" + std::to_string(args.size()) + "; it takes " +
                         std::to_string(names.size()) + ")");
    pyb::kwargs out;
    for (std::size_t i = 0; i < args.size(); ++i) out[pyb::str(names[i])] = args[i];
    for (const auto& [k, v] : kwargs) {
        if (out.contains(k)) throw InputError(what + ": '" + pyb::str(k).cast<std::string>() + "' given twice");
        out[k] = v;
    }
    for (const auto& r : required)
        if (!out.contains(r.c_str())) throw InputError(what + ": '" + r + "' is required");
    return out;
}

pyb::object from_value(const params::Value& v) {
    return std::visit([](const auto& x) -> pyb::object { return pyb::cast(x); }, v);
}

}  // namespace bvc3d::py

PYBIND11_MODULE(_core, m) {
    m.doc() = "bvc3d compiled core (use the `bvc3d` package)";
    m.attr("__version__") = BVC3D_VERSION;  // the project's version, from CMakeLists.txt
    static auto& input_error = pybind11::register_exception<bvc3d::InputError>(m, "InputError", PyExc_ValueError);
    // Messages may quote bytes of a file that are not UTF-8 (a Latin-1 or binary YAML): decode them
    // leniently, so that the message always arrives (pybind's own translation would lose it).
    pybind11::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const bvc3d::InputError& e) {
            const char* what = e.what();
            PyObject* text = PyUnicode_DecodeUTF8(what, static_cast<Py_ssize_t>(std::strlen(what)), "backslashreplace");
            PyErr_SetObject(input_error.ptr(), text);
            Py_XDECREF(text);
        } catch (const bvc3d::Interrupted&) {
            PyErr_SetNone(PyExc_KeyboardInterrupt);
        }
    });
    bvc3d::py::bind_simulator(m);
    bvc3d::py::bind_model(m);
    bvc3d::py::bind_experiment(m);
    bvc3d::py::bind_analysis(m);
    bvc3d::py::bind_recording(m);
    bvc3d::py::bind_place_recognition(m);  // after bind_analysis: it adds to bvc3d.analysis
    bvc3d::py::bind_buildings(m);
    bvc3d::py::bind_navigation(m);
    bvc3d::py::bind_authors(m);
    bvc3d::py::bind_populations(m);
    bvc3d::py::bind_growing(m);
}

#pragma once
// Shared helpers for the thin pybind11 layer over the C++ API. Parameter structs are bound
// through their tables (core/params.hpp): keyword arguments are the table's keys, every value is
// checked as YAML values are, and the defaults are the C++ struct's own.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <string>
#include <vector>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/params.hpp"

namespace bvc3d::py {

namespace pyb = pybind11;
using ArrayD = pyb::array_t<double, pyb::array::c_style | pyb::array::forcecast>;

// A fresh numpy array holding a copy of `n` values.
template <class T>
pyb::array_t<T> to_numpy(const T* data, std::vector<pyb::ssize_t> shape) {
    pyb::array_t<T> a(shape);
    std::size_t n = 1;
    for (auto s : shape) n *= static_cast<std::size_t>(s);
    if (n) std::memcpy(a.mutable_data(), data, n * sizeof(T));
    return a;
}

// A Python value as a table field's value (InputError naming the key if it has the wrong type).
params::Value to_value(const pyb::handle& obj, params::Kind kind, const std::string& key);
pyb::object from_value(const params::Value& v);

// Sets each keyword argument that names a field of `table` (the keys in `skip` are the caller's),
// then validates the struct. Unknown keywords are an error listing the accepted ones.
template <class S>
void apply_kwargs(S& s, const params::Table<S>& table, const pyb::kwargs& kwargs,
                  const std::vector<std::string>& skip = {}) {
    for (const auto& [k, v] : kwargs) {
        const std::string key = pyb::str(k);
        if (std::find(skip.begin(), skip.end(), key) != skip.end()) continue;
        const auto* f = table.find(key);
        if (!f) {
            std::string list;
            for (const auto& g : table.fields()) list += (list.empty() ? "" : ", ") + g.key;
            throw InputError(table.what() + ": unknown argument '" + key + "' (accepted: " + list + ")");
        }
        table.set(s, *f, to_value(v, f->kind, key));
    }
    s.validate();
}

// Positional arguments in the table's order, then keywords.
template <class S>
void apply_args(S& s, const params::Table<S>& table, const pyb::args& args, const pyb::kwargs& kwargs) {
    if (args.size() > table.fields().size()) throw InputError(table.what() + ": too many positional arguments");
    for (std::size_t i = 0; i < args.size(); ++i) {
        const auto& f = table.fields()[i];
        if (kwargs.contains(f.key.c_str())) throw InputError(table.what() + ": '" + f.key + "' given twice");
        table.set(s, f, to_value(args[i], f.kind, f.key));
    }
    apply_kwargs(s, table, kwargs);
}

// "key=default  description" lines for docstrings, from the table and a default struct.
template <class S>
std::string describe(const params::Table<S>& table, const S& defaults) {
    std::string out;
    for (const auto& f : table.fields())
        out += "  " + f.key + "=" + params::to_text(f.get(defaults)) + "  " + f.doc + (f.radians ? " (radians)" : "") + "\n";
    return out;
}

// Read-only properties for every field of the table.
template <class S, class C>
void def_fields(C& cls) {
    for (const auto& f : S::table().fields())
        cls.def_property_readonly(f.key.c_str(), [get = f.get](const S& s) { return from_value(get(s)); }, f.doc.c_str());
}

void bind_simulator(pyb::module_& m);
void bind_model(pyb::module_& m);
void bind_experiment(pyb::module_& m);
void bind_analysis(pyb::module_& m);
void bind_recording(pyb::module_& m);

}  // namespace bvc3d::py

#pragma once
// Shared helpers for the thin pybind11 layer over the C++ API.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <vector>

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

void bind_simulator(pyb::module_& m);
void bind_model(pyb::module_& m);
void bind_analysis(pyb::module_& m);

}  // namespace bvc3d::py

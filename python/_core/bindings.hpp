#pragma once
// Shared helpers for the thin pybind11 layer over the C++ API. Parameter structs are bound
// through their tables (core/params.hpp): keyword arguments are the table's keys, every value is
// checked as YAML values are, and the defaults are the C++ struct's own.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <exception>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/parallel.hpp"
#include "bvc3d/core/params.hpp"
#include "bvc3d/recorder/trial_record.hpp"
#include "bvc3d/world/world.hpp"

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

// A run's samples of its first model as arrays: t, x, y, z, heading, rates, weights, and bvc_rates
// when `with_bvc` (run_trial's and replay's dicts start from this).
pyb::dict samples_to_dict(const GroupResult& r, bool with_bvc);

// A user's path from a file path or a dict of arrays t, x, y, heading[, z, pitch, roll], its rows made
// model steps as the keywords of TrajectoryParams among `kwargs` say (step_per_row=, model_dt=).
std::shared_ptr<const TrajectorySpec> trajectory_of(const pyb::object& obj, const pyb::kwargs& kwargs);
std::vector<std::string> trajectory_keywords();  // those keywords

// An array of real numbers as float64, C order. Integers and floats convert; complex, object, text
// and boolean arrays are refused (a cast would drop imaginary parts or invent numbers).
ArrayD real_array(const pyb::handle& obj, const std::string& name);
// The same as float32 (the dtype of weights and rates), with the same refusals.
pyb::array_t<float, pyb::array::c_style | pyb::array::forcecast> real_array_f32(const pyb::handle& obj,
                                                                                const std::string& name);

// A seed: a Python integer 0 .. 2^64 - 1 (InputError naming `name` otherwise; no bools, no floats).
std::uint64_t seed_of(const pyb::handle& obj, const std::string& name);
// A whole number 0 .. 2^31 - 1 (a count of cells), InputError naming `name` otherwise.
int count_of(const pyb::handle& obj, const std::string& name);
// True or False (Python's or numpy's); anything else is an InputError naming `name` and the value's type.
bool flag_of(const pyb::handle& obj, const std::string& name);
// The name of a Python value's type, for messages that must not print the value (an array, a repr).
std::string type_name(const pyb::handle& obj);

// A call's arguments by name: positional ones take `names` in order, keywords their own; `required` must be given.
// A name given twice, too many positional arguments or a missing required one is an InputError naming `what`.
pyb::kwargs named_arguments(const std::string& what, const pyb::args& args, const pyb::kwargs& kwargs,
                            const std::vector<std::string>& names, const std::vector<std::string>& required = {});
// The keys of a parameter table, in its order.
template <class S>
std::vector<std::string> keys_of(const params::Table<S>& table, const std::vector<std::string>& skip = {}) {
    std::vector<std::string> keys;
    for (const auto& f : table.fields())
        if (std::find(skip.begin(), skip.end(), f.key) == skip.end()) keys.push_back(f.key);
    return keys;
}

// A world argument (`key` names it in errors): a World, or a preset name or a world file's path (str or
// os.PathLike), resolved. Anything else is an InputError naming its type, never its value. A World given is
// not copied: the pointer lives as long as the call's argument.
std::shared_ptr<const World> world_of(const pyb::handle& obj, const std::string& key);
// Where a world comes from, for what records it (a trial, a replay): a preset name or a file's path, or a World
// made from one (World.preset, World.cross, World.from_yaml, World.from_sdf without options). A World built in
// Python (from_dict, from_triangles, from_yaml_text, from_sdf with options) has none: an InputError says so.
WorldSpec world_source_of(const pyb::handle& obj, const std::string& key);
// Marks a World object with the source it was made from (what world_source_of reads).
pyb::object with_source(World world, const WorldSpec& source);

// Runs `work(stop)` on a worker of core/parallel.hpp's pool with the GIL released, and wakes every
// 100 ms to let Python run its signal handlers: Ctrl-C (KeyboardInterrupt) sets `stop` — which the
// work's loops poll, directly or through poll_cancel() — waits for the work to end (a fraction of a
// second) and raises the KeyboardInterrupt. Exceptions of the work are rethrown in the caller.
template <class F>
auto interruptible(F&& work) {
    using R = std::invoke_result_t<F&, const std::atomic<bool>&>;
    std::atomic<bool> interrupt{false};
    std::conditional_t<std::is_void_v<R>, bool, std::optional<R>> result{};
    bool interrupted = false;
    std::exception_ptr error;
    {
        pyb::gil_scoped_release release;
        const CancelScope scope(&interrupt);
        ParallelOptions options;
        options.tick_every = std::chrono::milliseconds(100);
        options.tick = [&] {
            if (interrupted) return;
            pyb::gil_scoped_acquire gil;
            if (PyErr_CheckSignals() != 0) interrupted = interrupt = true;  // the exception stays set
        };
        try {
            run_workers(
                1,
                [&](std::size_t) {
                    const std::atomic<bool>& stop = *cancel_flag();  // the pool's, set once `interrupt` is
                    if constexpr (std::is_void_v<R>) work(stop);
                    else result.emplace(work(stop));
                },
                options);
        } catch (...) {
            error = std::current_exception();
        }
    }
    if (interrupted) throw pyb::error_already_set();
    if (error) std::rethrow_exception(error);
    if constexpr (!std::is_void_v<R>) return std::move(*result);
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

// "key=default  description" lines for docstrings, from the table and a default struct (the keys in `skip` aside).
template <class S>
std::string describe(const params::Table<S>& table, const S& defaults, const std::vector<std::string>& skip = {}) {
    std::string out;
    for (const auto& f : table.fields())
        if (std::find(skip.begin(), skip.end(), f.key) == skip.end())
            out += "  " + f.key + "=" + params::to_text(f.get(defaults)) + "  " + f.doc +
                   (f.radians ? " (radians)" : "") + "\n";
    return out;
}

// Read-only properties for every field of the table.
template <class S, class C>
void def_fields(C& cls) {
    for (const auto& f : S::table().fields())
        cls.def_property_readonly(
            f.key.c_str(), [get = f.get](const S& s) { return from_value(get(s)); }, f.doc.c_str());
}

void bind_simulator(pyb::module_& m);
void bind_model(pyb::module_& m);
void bind_experiment(pyb::module_& m);
void bind_analysis(pyb::module_& m);
void bind_recording(pyb::module_& m);
void bind_place_recognition(pyb::module_& m);
void bind_buildings(pyb::module_& m);  // after bind_simulator: it adds to World
void bind_navigation(pyb::module_& m);
void bind_authors(pyb::module_& m);
void bind_populations(pyb::module_& m);
void bind_growing(pyb::module_& m);

}  // namespace bvc3d::py

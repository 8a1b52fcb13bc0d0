#include "bvc3d/recorder/checkpoint_file.hpp"

#include <algorithm>
#include <sstream>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/recorder/hdf5_io.hpp"

namespace bvc3d {

namespace {

// Version 2: every population's state by name (version 1, before populations, held the place cells' only).
constexpr std::int64_t checkpoint_version = 2;

// The recorded streams of a group, in a fixed order: per model its place-cell rates, BVC rates and each other
// population's rates.
template <class Result>
auto streams(Result& r) {
    std::vector<decltype(&r.models.front().rates)> out;
    for (auto& m : r.models) {
        out.push_back(&m.rates);
        out.push_back(&m.bvc);
        for (auto& p : m.populations) out.push_back(&p.rates);
    }
    return out;
}

void write_state(hid_t group, const StateArray& a) {
    std::visit([&](const auto& v) { h5::write(group, a.name, v, {v.size()}, false); }, a.values);
    std::string shape;
    for (std::size_t d : a.shape) {
        if (!shape.empty()) shape += ' ';
        shape += std::to_string(d);
    }
    h5::write_attr(group, "shape:" + a.name, shape);
}

StateArray read_state(hid_t group, const std::string& name) {
    StateArray a;
    a.name = name;
    if (h5::element(group, name) == h5::Element::f32) a.values = h5::read_floats(group, name);
    else a.values = h5::read_doubles(group, name);
    std::istringstream shape(h5::read_attr_string(group, "shape:" + name));
    for (std::size_t d; shape >> d;) a.shape.push_back(d);
    return a;
}

std::filesystem::path segment_path(const std::filesystem::path& state, std::size_t k) {
    std::filesystem::path p = state;
    p += ".seg" + std::to_string(k);
    return p;
}

void write_segment(const std::filesystem::path& path, const GroupResult& r) {
    AtomicFile out(path);
    std::string image;
    {
        auto lock = h5::hdf5_lock();
        const auto f = h5::create_memory_file(out.temp_path().string());
        const std::size_t n = r.t.size();
        h5::write_attr(f, "format", std::string("bvc3d-checkpoint-segment"));
        h5::write_attr(f, "samples", static_cast<std::int64_t>(n));
        h5::write(f, "t", r.t, {n});
        h5::write(f, "x", r.x, {n});
        h5::write(f, "y", r.y, {n});
        h5::write(f, "z", r.z, {n});
        h5::write(f, "heading", r.heading, {n});
        const auto all = streams(r);
        for (std::size_t i = 0; i < all.size(); ++i)
            h5::write(f, "stream" + std::to_string(i), *all[i], {all[i]->size()});
        image = h5::file_image(f);
    }
    out.write(image);
    out.commit();
}

template <class T>
void append(std::vector<T>& to, const std::vector<T>& from) {
    to.insert(to.end(), from.begin(), from.end());
}

void read_segment(const std::filesystem::path& path, GroupResult& r) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError("its segment '" + path.string() + "' is missing");
    auto lock = h5::hdf5_lock();
    try {
        const auto f = h5::open_file(path.string());
        if (h5::read_attr_string(f, "format") != "bvc3d-checkpoint-segment")
            throw InputError("not a checkpoint segment");
        append(r.t, h5::read_doubles(f, "t"));
        append(r.x, h5::read_doubles(f, "x"));
        append(r.y, h5::read_doubles(f, "y"));
        append(r.z, h5::read_doubles(f, "z"));
        append(r.heading, h5::read_doubles(f, "heading"));
        const auto all = streams(r);
        for (std::size_t i = 0; i < all.size(); ++i) append(*all[i], h5::read_floats(f, "stream" + std::to_string(i)));
    } catch (const InputError& e) {
        throw InputError("its segment '" + path.string() + "' is unreadable (" + e.what() + ")");
    }
}

}  // namespace

void write_checkpoint(const std::filesystem::path& path, GroupCheckpoint& c) {
    const std::size_t fresh = c.partial.t.size();
    if (fresh > 0) write_segment(segment_path(path, c.segments), c.partial);
    const std::size_t segments = c.segments + (fresh > 0 ? 1 : 0), saved = c.saved + fresh;
    AtomicFile out(path);
    std::string image;
    {
        auto lock = h5::hdf5_lock();
        const auto f = h5::create_memory_file(out.temp_path().string());
        h5::write_attr(f, "format", std::string("bvc3d-checkpoint"));
        h5::write_attr(f, "version", checkpoint_version);
        h5::write_attr(f, "fingerprint", c.fingerprint);
        h5::write_attr(f, "segments", static_cast<std::int64_t>(segments));
        h5::write_attr(f, "samples", static_cast<std::int64_t>(saved));
        h5::write_attr(f, "step_index", c.step_index);
        h5::write_attr(f, "agent_state", c.agent_state);
        const auto& s = c.partial.stats;
        h5::write_attr(f, "explore_steps", s.explore_steps);
        h5::write_attr(f, "sample_steps", s.sample_steps);
        h5::write_attr(f, "bumps", s.bumps);
        h5::write_attr(f, "full_scan_fallbacks", s.full_scan_fallbacks);
        h5::write_attr(f, "n_models", static_cast<std::int64_t>(c.partial.models.size()));
        for (std::size_t i = 0; i < c.partial.models.size(); ++i) {
            const auto& m = c.partial.models[i];
            const auto g = h5::create_group(f, "model" + std::to_string(i));
            h5::write_attr(g, "n_place", static_cast<std::int64_t>(m.n_place));
            h5::write_attr(g, "n_bvc", static_cast<std::int64_t>(m.n_bvc));
            h5::write_attr(g, "populations", static_cast<std::int64_t>(m.populations.size()));
            for (std::size_t k = 0; k < m.populations.size(); ++k) {
                const auto& p = m.populations[k];
                h5::write_attr(g, "name" + std::to_string(k), p.name);
                h5::write_attr(g, "cells" + std::to_string(k), static_cast<std::int64_t>(p.cells));
                h5::write_attr(g, "recorded" + std::to_string(k), static_cast<std::int64_t>(p.recorded));
            }
        }
        // Dense: compression would only cost time.
        h5::write_attr(f, "n_states", static_cast<std::int64_t>(c.states.size()));
        for (std::size_t j = 0; j < c.states.size(); ++j) {
            const auto g = h5::create_group(f, "state" + std::to_string(j));
            h5::write_attr(g, "arrays", static_cast<std::int64_t>(c.states[j].size()));
            for (std::size_t a = 0; a < c.states[j].size(); ++a) {
                h5::write_attr(g, "array" + std::to_string(a), c.states[j][a].name);
                write_state(g, c.states[j][a]);
            }
        }
        image = h5::file_image(f);
    }
    out.write(image);
    out.commit();
    c.segments = segments;
    c.saved = saved;
}

CheckpointRead read_checkpoint(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return {};
    const auto broken = [&](const std::string& why) {
        return CheckpointRead{std::nullopt, "checkpoint '" + path.string() + "' " + why};
    };
    GroupCheckpoint c;
    try {
        auto lock = h5::hdf5_lock();
        const auto f = h5::open_file(path.string());
        if (h5::read_attr_string(f, "format") != "bvc3d-checkpoint") return broken("is not a bvc3d checkpoint");
        if (!h5::exists_attr(f, "version") || h5::read_attr_int(f, "version") != checkpoint_version)
            return broken("was written by another version of bvc3d");
        c.fingerprint = h5::read_attr_string(f, "fingerprint");
        const auto segments = h5::read_attr_int(f, "segments"), saved = h5::read_attr_int(f, "samples");
        const auto n_models = h5::read_attr_int(f, "n_models");
        if (segments < 0 || saved < 0 || n_models < 0 || n_models > 1000000) return broken("has impossible counts");
        c.segments = static_cast<std::size_t>(segments);
        c.saved = static_cast<std::size_t>(saved);
        c.step_index = h5::read_attr_int(f, "step_index");
        c.agent_state = h5::read_attr_string(f, "agent_state");
        auto& s = c.partial.stats;
        s.explore_steps = h5::read_attr_int(f, "explore_steps");
        s.sample_steps = h5::read_attr_int(f, "sample_steps");
        s.bumps = h5::read_attr_int(f, "bumps");
        s.full_scan_fallbacks = h5::read_attr_int(f, "full_scan_fallbacks");
        for (std::int64_t i = 0; i < n_models; ++i) {
            const auto mg = h5::open_group(f, "model" + std::to_string(i));
            ModelRecord m;
            m.n_place = static_cast<int>(h5::read_attr_int(mg, "n_place"));
            m.n_bvc = static_cast<int>(h5::read_attr_int(mg, "n_bvc"));
            const auto n_populations = h5::read_attr_int(mg, "populations");
            if (n_populations < 0 || n_populations > 100000) return broken("has impossible counts");
            for (std::int64_t k = 0; k < n_populations; ++k) {
                PopulationRecord p;
                p.name = h5::read_attr_string(mg, "name" + std::to_string(k));
                p.cells = static_cast<std::size_t>(
                    std::max<std::int64_t>(0, h5::read_attr_int(mg, "cells" + std::to_string(k))));
                p.recorded = h5::read_attr_int(mg, "recorded" + std::to_string(k)) != 0;
                m.populations.push_back(std::move(p));
            }
            c.partial.models.push_back(std::move(m));
        }
        const auto n_states = h5::read_attr_int(f, "n_states");
        if (n_states < 0 || n_states > 1000000) return broken("has impossible counts");
        for (std::int64_t j = 0; j < n_states; ++j) {
            const auto g = h5::open_group(f, "state" + std::to_string(j));
            std::vector<StateArray> arrays;
            for (std::int64_t a = 0, n = h5::read_attr_int(g, "arrays"); a < n; ++a)
                arrays.push_back(read_state(g, h5::read_attr_string(g, "array" + std::to_string(a))));
            c.states.push_back(std::move(arrays));
        }
        for (std::size_t k = 0; k < c.segments; ++k) read_segment(segment_path(path, k), c.partial);
    } catch (const InputError& e) {
        const std::string why = e.what();
        return broken(why.rfind("its segment", 0) == 0 ? why : "is unreadable or truncated (" + why + ")");
    }
    if (c.partial.t.size() != c.saved)
        return broken("holds " + std::to_string(c.partial.t.size()) + " samples in its segments, not the " +
                      std::to_string(c.saved) + " it lists");
    for (const auto& m : c.partial.models) {
        if (m.n_place < 1 || m.rates.size() != c.saved * static_cast<std::size_t>(m.n_place))
            return broken("has arrays of the wrong size");
        for (const auto& p : m.populations)
            if (p.rates.size() != (p.recorded ? c.saved * p.cells : 0)) return broken("has arrays of the wrong size");
    }
    return {std::move(c), ""};
}

void remove_checkpoint(const std::filesystem::path& path) {
    std::error_code ec;
    std::filesystem::remove(path, ec);
    for (std::size_t k = 0; std::filesystem::remove(segment_path(path, k), ec); ++k) {}
}

}  // namespace bvc3d

#include "bvc3d/recorder/checkpoint_file.hpp"

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/recorder/hdf5_io.hpp"

namespace bvc3d {

namespace {

void write_samples(hid_t f, const GroupResult& r) {
    const auto g = h5::create_group(f, "samples");
    const std::size_t n = r.t.size();
    h5::write(g, "t", r.t, {n});
    h5::write(g, "x", r.x, {n});
    h5::write(g, "y", r.y, {n});
    h5::write(g, "heading", r.heading, {n});
}

}  // namespace

void write_checkpoint(const std::filesystem::path& path, const GroupCheckpoint& c) {
    AtomicFile out(path);
    {
        auto lock = h5::hdf5_lock();
        const auto f = h5::create_file(out.temp_path().string());
        h5::write_attr(f, "format", std::string("bvc3d-checkpoint"));
        h5::write_attr(f, "fingerprint", c.fingerprint);
        h5::write_attr(f, "step_index", c.step_index);
        h5::write_attr(f, "walk_x", c.walk.pose.x);
        h5::write_attr(f, "walk_y", c.walk.pose.y);
        h5::write_attr(f, "walk_heading", c.walk.pose.heading);
        h5::write_attr(f, "walk_t", c.walk.t);
        h5::write_attr(f, "walk_steps_since_turn", static_cast<std::int64_t>(c.walk.steps_since_turn));
        h5::write_attr(f, "walk_bump_pending", static_cast<std::int64_t>(c.walk.bump_pending));
        h5::write_attr(f, "walk_rng", c.walk.rng_state);
        const auto& s = c.partial.stats;
        h5::write_attr(f, "explore_steps", s.explore_steps);
        h5::write_attr(f, "sample_steps", s.sample_steps);
        h5::write_attr(f, "bumps", s.bumps);
        h5::write_attr(f, "full_scan_fallbacks", s.full_scan_fallbacks);
        h5::write_attr(f, "n_models", static_cast<std::int64_t>(c.partial.models.size()));
        write_samples(f, c.partial);
        for (std::size_t i = 0; i < c.partial.models.size(); ++i) {
            const auto& m = c.partial.models[i];
            const auto g = h5::create_group(f, "model" + std::to_string(i));
            h5::write_attr(g, "n_place", static_cast<std::int64_t>(m.n_place));
            h5::write_attr(g, "n_bvc", static_cast<std::int64_t>(m.n_bvc));
            h5::write(g, "rates", m.rates, {m.rates.size()});
            h5::write(g, "bvc", m.bvc, {m.bvc.size()});
            h5::write(g, "weights", m.weights, {m.weights.size()});
            h5::write(g, "membrane", c.membrane[i], {c.membrane[i].size()}, false);
            h5::write(g, "place_rates", c.place_rates[i], {c.place_rates[i].size()}, false);
        }
    }
    out.commit();
}

std::optional<GroupCheckpoint> read_checkpoint(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) return std::nullopt;
    try {
        auto lock = h5::hdf5_lock();
        const auto f = h5::open_file(path.string());
        if (h5::read_attr_string(f, "format") != "bvc3d-checkpoint") return std::nullopt;
        GroupCheckpoint c;
        c.fingerprint = h5::read_attr_string(f, "fingerprint");
        c.step_index = h5::read_attr_int(f, "step_index");
        c.walk.pose = {h5::read_attr_double(f, "walk_x"), h5::read_attr_double(f, "walk_y"),
                       h5::read_attr_double(f, "walk_heading")};
        c.walk.t = h5::read_attr_double(f, "walk_t");
        c.walk.steps_since_turn = static_cast<int>(h5::read_attr_int(f, "walk_steps_since_turn"));
        c.walk.bump_pending = h5::read_attr_int(f, "walk_bump_pending") != 0;
        c.walk.rng_state = h5::read_attr_string(f, "walk_rng");
        auto& s = c.partial.stats;
        s.explore_steps = h5::read_attr_int(f, "explore_steps");
        s.sample_steps = h5::read_attr_int(f, "sample_steps");
        s.bumps = h5::read_attr_int(f, "bumps");
        s.full_scan_fallbacks = h5::read_attr_int(f, "full_scan_fallbacks");
        const auto g = h5::open_group(f, "samples");
        c.partial.t = h5::read_doubles(g, "t");
        c.partial.x = h5::read_doubles(g, "x");
        c.partial.y = h5::read_doubles(g, "y");
        c.partial.heading = h5::read_doubles(g, "heading");
        const auto n_models = h5::read_attr_int(f, "n_models");
        for (std::int64_t i = 0; i < n_models; ++i) {
            const auto mg = h5::open_group(f, "model" + std::to_string(i));
            ModelRecord m;
            m.n_place = static_cast<int>(h5::read_attr_int(mg, "n_place"));
            m.n_bvc = static_cast<int>(h5::read_attr_int(mg, "n_bvc"));
            m.rates = h5::read_floats(mg, "rates");
            m.bvc = h5::read_floats(mg, "bvc");
            m.weights = h5::read_floats(mg, "weights");
            c.membrane.push_back(h5::read_floats(mg, "membrane"));
            c.place_rates.push_back(h5::read_floats(mg, "place_rates"));
            c.partial.models.push_back(std::move(m));
        }
        return c;
    } catch (const InputError&) {
        return std::nullopt;
    }
}

}  // namespace bvc3d

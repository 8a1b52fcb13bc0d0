#include "bvc3d/recorder/trial_file.hpp"

#include <algorithm>
#include <sstream>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/recorder/hdf5_io.hpp"

namespace bvc3d {

namespace {

void write_identity(hid_t f, const TrialIdentity& id) {
    h5::write_attr(f, "format", std::string("bvc3d-trial"));
    h5::write_attr(f, "format_version", static_cast<std::int64_t>(trial_file_format_version));
    h5::write_attr(f, "name", id.name);
    h5::write_attr(f, "condition", id.condition);
    std::string swept;
    for (const auto& [k, v] : id.swept) swept += k + "=" + v + "\n";
    h5::write_attr(f, "swept", swept);
    h5::write_attr(f, "world", id.world);
    h5::write_attr(f, "world_source", id.world_source);
    if (std::isfinite(id.tilt_deg)) h5::write_attr(f, "tilt_deg", id.tilt_deg);
    h5::write_attr(f, "model", id.model);
    h5::write_attr(f, "sensor", id.sensor);
    h5::write_attr(f, "seed", static_cast<std::int64_t>(id.seed));
    h5::write_attr(f, "protocol", id.protocol);
    h5::write_attr(f, "explore_hours", id.explore_hours);
    h5::write_attr(f, "sample_hours", id.sample_hours);
    h5::write_attr(f, "config", id.config);
    h5::write_attr(f, "fingerprint", id.fingerprint);
    for (const auto& [name, value] : id.data_source) h5::write_attr(f, name, value);
}

void write_array(hid_t loc, const NamedArray& a) {
    std::visit([&](const auto& v) { h5::write(loc, a.name, v, a.shape, a.compress); }, a.data);
}

void write_metrics(hid_t f, const MetricsRecord& m) {
    const auto g = h5::create_group(f, "metrics");
    for (const auto& [name, value] : m.scalars) h5::write_attr(g, name, value);
    for (const auto& [name, value] : m.parameters) h5::write_attr(g, name, value);
    for (const auto& a : m.arrays) write_array(g, a);
}

}  // namespace

void write_trial_file(const std::filesystem::path& path, const TrialIdentity& id, const GroupResult& group,
                      std::size_t model_index, const MetricsRecord& metrics) {
    const ModelRecord& rec = group.models.at(model_index);
    const std::size_t n = group.t.size();
    AtomicFile out(path);
    {
        auto lock = h5::hdf5_lock();
        const auto f = h5::create_file(out.temp_path().string());
        write_identity(f, id);
        const auto s = h5::create_group(f, "samples");
        h5::write(s, "t", group.t, {n});
        h5::write(s, "x", group.x, {n});
        h5::write(s, "y", group.y, {n});
        if (std::any_of(group.z.begin(), group.z.end(), [](double z) { return z != 0.0; })) h5::write(s, "z", group.z, {n});
        h5::write(s, "heading", group.heading, {n});
        h5::write(s, "rates", rec.rates, {n, static_cast<std::size_t>(rec.n_place)});
        if (!rec.bvc.empty()) h5::write(s, "bvc_rates", rec.bvc, {n, static_cast<std::size_t>(rec.n_bvc)});
        h5::write(f, "weights", rec.weights, {static_cast<std::size_t>(rec.n_place), static_cast<std::size_t>(rec.n_bvc)});

        const auto w = h5::create_group(f, "walk");
        h5::write_attr(w, "explore_steps", group.stats.explore_steps);
        h5::write_attr(w, "sample_steps", group.stats.sample_steps);
        h5::write_attr(w, "bumps", group.stats.bumps);
        h5::write_attr(w, "full_scan_fallbacks", group.stats.full_scan_fallbacks);
        h5::write_attr(w, "end_time", group.stats.end_time);
        write_metrics(f, metrics);
    }
    out.commit();
}

std::optional<TrialStamp> read_trial_stamp(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;
    try {
        auto lock = h5::hdf5_lock();
        const auto f = h5::open_file(path.string());
        if (h5::read_attr_string(f, "format") != "bvc3d-trial") return std::nullopt;
        if (!h5::exists(f, "metrics")) return std::nullopt;
        return TrialStamp{h5::read_attr_string(f, "fingerprint"), h5::attribute_names(h5::open_group(f, "metrics"))};
    } catch (const InputError&) {
        return std::nullopt;
    }
}

namespace {

h5::Handle open_trial(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
        throw InputError("trial file '" + path.string() + "' does not exist");
    auto f = h5::open_file(path.string());
    std::string format;
    try {
        format = h5::read_attr_string(f, "format");
    } catch (const InputError&) {
    }
    if (format != "bvc3d-trial") throw InputError("'" + path.string() + "' is not a bvc3d trial file");
    return f;
}

TrialIdentity read_identity(hid_t f) {
    TrialIdentity id;
    auto text = [&](const char* name) { return h5::exists_attr(f, name) ? h5::read_attr_string(f, name) : std::string(); };
    auto number = [&](const char* name) { return h5::exists_attr(f, name) ? h5::read_attr_double(f, name) : NAN; };
    id.name = h5::read_attr_string(f, "name");
    id.world = h5::read_attr_string(f, "world");
    id.model = h5::read_attr_string(f, "model");
    id.seed = static_cast<std::uint64_t>(h5::read_attr_int(f, "seed"));
    id.tilt_deg = number("tilt_deg");
    id.world_source = text("world_source");
    id.sensor = text("sensor");
    id.protocol = text("protocol");
    id.config = text("config");
    id.fingerprint = text("fingerprint");
    id.explore_hours = number("explore_hours");
    id.sample_hours = number("sample_hours");
    // Files from before conditions were recorded: the paper's condition, model and world.
    id.condition = h5::exists_attr(f, "condition") ? h5::read_attr_string(f, "condition") : id.world + "_" + id.model;
    std::istringstream swept(text("swept"));
    for (std::string line; std::getline(swept, line);) {
        const auto eq = line.find('=');
        if (eq != std::string::npos) id.swept.emplace_back(line.substr(0, eq), line.substr(eq + 1));
    }
    return id;
}

}  // namespace

TrialFileData read_trial_samples(const std::filesystem::path& path) {
    auto lock = h5::hdf5_lock();
    const auto f = open_trial(path);
    TrialFileData d;
    static_cast<TrialIdentity&>(d) = read_identity(f);
    const auto g = h5::open_group(f, "metrics");
    for (const auto& name : h5::attribute_names(g)) d.metric_attributes.emplace_back(name, h5::read_attr(g, name));
    if (h5::exists(g, "extent")) d.extent = h5::read_doubles(g, "extent");
    const auto s = h5::open_group(f, "samples");
    d.x = h5::read_doubles(s, "x");
    d.y = h5::read_doubles(s, "y");
    if (h5::exists(s, "z")) d.z = h5::read_doubles(s, "z");
    const auto dims = h5::dims(s, "rates");
    if (dims.size() != 2 || dims[0] != d.x.size() || d.y.size() != d.x.size() || (!d.z.empty() && d.z.size() != d.x.size()))
        throw InputError("'" + path.string() + "': samples/rates has the wrong shape");
    d.rates = h5::read_floats(s, "rates");
    d.n_place = dims[1];
    return d;
}

TrialRates read_trial_rates(const std::filesystem::path& path, bool bvc) {
    auto lock = h5::hdf5_lock();
    const auto f = open_trial(path);
    const auto s = h5::open_group(f, "samples");
    const char* name = bvc ? "bvc_rates" : "rates";
    if (!h5::exists(s, name))
        throw InputError("trial file '" + path.string() + "' has no " + (bvc ? "BVC rates (samples/bvc_rates): rerun it recording them" : "samples/rates"));
    TrialRates r;
    r.t = h5::read_doubles(s, "t");
    r.x = h5::read_doubles(s, "x");
    r.y = h5::read_doubles(s, "y");
    r.z = h5::exists(s, "z") ? h5::read_doubles(s, "z") : std::vector<double>(r.x.size(), 0.0);
    r.heading = h5::read_doubles(s, "heading");
    const auto dims = h5::dims(s, name);
    const std::size_t n = r.x.size();
    if (dims.size() != 2 || dims[0] != n || r.y.size() != n || r.z.size() != n || r.t.size() != n || r.heading.size() != n)
        throw InputError("trial file '" + path.string() + "': samples/" + name + " has the wrong shape");
    r.rates = h5::read_floats(s, name);
    r.n_cells = dims[1];
    return r;
}

TrialWeights read_trial_weights(const std::filesystem::path& path) {
    auto lock = h5::hdf5_lock();
    const auto f = open_trial(path);
    if (!h5::exists(f, "weights")) throw InputError("trial file '" + path.string() + "' has no weights");
    const auto dims = h5::dims(f, "weights");
    if (dims.size() != 2) throw InputError("trial file '" + path.string() + "': weights has the wrong shape");
    TrialWeights w;
    w.values = h5::read_floats(f, "weights");
    w.n_place = dims[0];
    w.n_bvc = dims[1];
    return w;
}

std::optional<NamedArray> read_trial_array(const std::filesystem::path& path, const std::string& dataset) {
    auto lock = h5::hdf5_lock();
    const auto f = open_trial(path);
    // Walk the groups one name at a time: H5Lexists needs every link on the way to exist.
    std::vector<h5::Handle> groups;
    hid_t loc = f;
    std::string rest = dataset;
    for (auto slash = rest.find('/'); slash != std::string::npos; slash = rest.find('/')) {
        const std::string group = rest.substr(0, slash);
        if (group.empty() || !h5::exists(loc, group)) return std::nullopt;
        groups.push_back(h5::open_group(loc, group));
        loc = groups.back();
        rest = rest.substr(slash + 1);
    }
    if (rest.empty() || !h5::exists(loc, rest)) return std::nullopt;
    NamedArray a{dataset, h5::dims(loc, rest), {}, true};
    switch (h5::element(loc, rest)) {
        case h5::Element::f64: a.data = h5::read_doubles(loc, rest); break;
        case h5::Element::f32: a.data = h5::read_floats(loc, rest); break;
        case h5::Element::integer: a.data = h5::read_ints(loc, rest); break;
        case h5::Element::other:
            throw InputError("'" + path.string() + "': dataset '" + dataset + "' holds neither numbers nor integers");
    }
    return a;
}

TrialSummaryRow read_trial_summary(const std::filesystem::path& path, const std::vector<std::string>& metric_names) {
    auto lock = h5::hdf5_lock();
    const auto f = open_trial(path);
    TrialSummaryRow r;
    static_cast<TrialIdentity&>(r) = read_identity(f);
    const auto g = h5::open_group(f, "metrics");
    for (const auto& name : metric_names)
        r.metrics.emplace_back(name, h5::exists_attr(g, name) ? h5::read_attr_double(g, name) : NAN);
    return r;
}

}  // namespace bvc3d

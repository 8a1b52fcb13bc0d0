#include "bvc3d/recorder/trial_file.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <type_traits>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/navigation/failure_class.hpp"
#include "bvc3d/recorder/hdf5_io.hpp"

namespace bvc3d {

namespace {

void write_identity(hid_t f, const TrialIdentity& id) {
    h5::write_attr(f, "format", std::string("bvc3d-trial"));
    h5::write_attr(f, "format_version", static_cast<std::int64_t>(trial_file_version_for(id.dims)));
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
    h5::write_attr_u64(f, "seed", id.seed);  // all of 0 .. 2^64 - 1, no sign change
    h5::write_attr(f, "protocol", id.protocol);
    h5::write_attr(f, "explore_hours", id.explore_hours);
    h5::write_attr(f, "sample_hours", id.sample_hours);
    h5::write_attr(f, "config", id.config);
    h5::write_attr(f, "fingerprint", id.fingerprint);
    if (!id.place_weights.empty()) h5::write_attr(f, "place_weights", id.place_weights);
    if (!id.place_weights_source.empty()) h5::write_attr(f, "place_weights_source", id.place_weights_source);
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

// A model's other populations: /populations/NAME/ with its rates (samples × cells), what it keeps (weights ...) and
// its metrics.
void write_populations(hid_t f, const ModelRecord& rec, std::size_t n,
                       const std::vector<std::pair<std::string, MetricsRecord>>& metrics) {
    if (rec.populations.empty()) return;
    const auto all = h5::create_group(f, "populations");
    for (const PopulationRecord& p : rec.populations) {
        const auto g = h5::create_group(all, p.name);
        if (p.recorded) h5::write(g, "rates", p.rates, {n, p.cells});
        for (const StateArray& a : p.kept)
            std::visit([&](const auto& v) { h5::write(g, a.name, v, a.shape); }, a.values);
        for (const auto& [name, m] : metrics)
            if (name == p.name) write_metrics(g, m);
    }
    // Metrics of no population of its own (a multiscale model's scales fused): a group with the metrics alone.
    for (const auto& entry : metrics)
        if (std::none_of(rec.populations.begin(), rec.populations.end(),
                         [&](const PopulationRecord& p) { return p.name == entry.first; }))
            write_metrics(h5::create_group(all, entry.first), entry.second);
}

std::vector<std::int64_t> ints(const std::vector<int>& v) { return {v.begin(), v.end()}; }

// /navigation (docs/trial-files.md#navigation): the learning walk's end, the reward cells, every start and its path,
// the first scale's reward map. Numbers as computed (float64), counts and indices as int64.
void write_navigation(hid_t f, const NavigationRecord& r) {
    const auto g = h5::create_group(f, "navigation");
    const auto d = static_cast<std::size_t>(r.dims), G = r.n_goals(), N = r.n_starts();
    h5::write_attr(g, "dims", static_cast<std::int64_t>(r.dims));
    h5::write_attr(g, "learn_s", r.learn_s);
    h5::write_attr(g, "coverage", r.coverage);
    std::string scales;
    for (const auto& name : r.scales) scales += (scales.empty() ? "" : "\n") + name;
    h5::write_attr(g, "scales", scales);
    h5::write(g, "goals", r.goals, {G, d});
    h5::write(g, "visits", ints(r.visits), {G});
    h5::write(g, "goal_cells", ints(r.goal_cells), {r.scales.size(), G});
    h5::write(g, "start_goal", ints(r.start_goal), {N});
    h5::write(g, "start", r.start, {N, d});
    h5::write(g, "success", ints(r.success), {N});
    h5::write(g, "path_m", r.path_m, {N});
    h5::write(g, "shortest_m", r.shortest_m, {N});
    h5::write(g, "time_s", r.time_s, {N});
    h5::write(g, "path_start", std::vector<std::int64_t>(r.path_start.begin(), r.path_start.end()), {N + 1});
    h5::write(g, "path", r.path, {r.path.size() / d, d});
    h5::write(g, "map_points", r.map_points, {r.map_points.size() / 2, 2});
    h5::write(g, "map_reward", r.map_reward, {G, r.map_points.size() / 2});
    h5::write(g, "failure", ints(r.failure), {r.failure.size()});
    h5::write(g, "walls", r.walls, {r.walls.size() / 4, 4});
}

}  // namespace

void write_trial_file(const std::filesystem::path& path, const TrialIdentity& id, const GroupResult& group,
                      std::size_t model_index, const MetricsRecord& metrics,
                      const std::vector<std::pair<std::string, MetricsRecord>>& population_metrics) {
    const ModelRecord& rec = group.models.at(model_index);
    const std::size_t n = group.t.size();
    AtomicFile out(path);
    std::string image;
    {
        auto lock = h5::hdf5_lock();
        const auto f = h5::create_memory_file(out.temp_path().string());
        write_identity(f, id);
        const auto s = h5::create_group(f, "samples");
        h5::write(s, "t", group.t, {n});
        h5::write(s, "x", group.x, {n});
        h5::write(s, "y", group.y, {n});
        if (id.dims == 3 || std::any_of(group.z.begin(), group.z.end(), [](double z) { return z != 0.0; }))
            h5::write(s, "z", group.z, {n});
        h5::write(s, "heading", group.heading, {n});
        h5::write(s, "rates", rec.rates, {n, static_cast<std::size_t>(rec.n_place)});
        if (!rec.bvc.empty()) h5::write(s, "bvc_rates", rec.bvc, {n, static_cast<std::size_t>(rec.n_bvc)});
        h5::write(f, "weights", rec.weights,
                  {static_cast<std::size_t>(rec.n_place), static_cast<std::size_t>(rec.n_bvc)});
        if (!id.model_config.empty()) {
            const h5::Handle weights(H5Dopen2(f, "weights", H5P_DEFAULT), H5Dclose);
            h5::write_attr(weights, "model", id.model);
            h5::write_attr(weights, "model_config", id.model_config);
        }

        const auto w = h5::create_group(f, "walk");
        h5::write_attr(w, "explore_steps", group.stats.explore_steps);
        h5::write_attr(w, "sample_steps", group.stats.sample_steps);
        h5::write_attr(w, "bumps", group.stats.bumps);
        h5::write_attr(w, "full_scan_fallbacks", group.stats.full_scan_fallbacks);
        h5::write_attr(w, "end_time", group.stats.end_time);
        write_metrics(f, metrics);
        write_populations(f, rec, n, population_metrics);
        for (const NavigationRecord& nav : rec.navigation) write_navigation(f, nav);
        image = h5::file_image(f);
    }
    out.write(image);
    out.commit();
}

namespace {

// Files without the attribute predate it: version 1.
int format_version(hid_t f) {
    return h5::exists_attr(f, "format_version") ? static_cast<int>(h5::read_attr_int(f, "format_version")) : 1;
}

std::string version_error(const std::filesystem::path& path, int v) {
    return "trial file '" + path.string() + "' has format_version " + std::to_string(v) +
           "; this bvc3d reads versions 1 to " + std::to_string(trial_file_format_version) +
           " (written by a newer bvc3d? docs/trial-files.md)";
}

}  // namespace

std::optional<TrialStamp> read_trial_stamp(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return std::nullopt;
    int version = 1;
    std::optional<TrialStamp> stamp;
    try {
        auto lock = h5::hdf5_lock();
        const auto f = h5::open_file(path.string());
        if (h5::read_attr_string(f, "format") != "bvc3d-trial") return std::nullopt;
        version = format_version(f);
        if (h5::exists(f, "metrics"))
            stamp = TrialStamp{h5::read_attr_string(f, "fingerprint"),
                               h5::attribute_names(h5::open_group(f, "metrics")), h5::exists(f, "navigation")};
    } catch (const InputError&) {
        return std::nullopt;
    }
    // A newer bvc3d's file is not broken: say so rather than overwrite it.
    if (version < 1 || version > trial_file_format_version) throw InputError(version_error(path, version));
    return stamp;
}

bool is_trial_file(const std::filesystem::path& path) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) return false;
    try {
        auto lock = h5::hdf5_lock();
        return h5::read_attr_string(h5::open_file(path.string()), "format") == "bvc3d-trial";
    } catch (const InputError&) {
        return false;
    }
}

namespace {

// Reading a trial file: every error names the file and the dataset or attribute.
class TrialReader {
public:
    explicit TrialReader(const std::filesystem::path& path) : path_(path) {
        std::error_code ec;
        if (std::filesystem::is_directory(path, ec)) fail("is a folder, not a file");
        if (!std::filesystem::exists(path, ec)) fail("does not exist");
        try {
            file_ = h5::open_file(path.string());
        } catch (const InputError&) {
            fail("is not an HDF5 file, or is truncated or damaged");
        }
        if (!h5::exists_attr(file_, "format") || h5::attr_class(file_, "format") != H5T_STRING ||
            h5::read_attr_string(file_, "format") != "bvc3d-trial")
            fail("is not a bvc3d trial file (its 'format' attribute is not 'bvc3d-trial')");
        // Files of the first version may lack the attribute.
        if (h5::exists_attr(file_, "format_version")) {
            if (h5::attr_class(file_, "format_version") != H5T_INTEGER)
                fail("attribute 'format_version' is not an integer");
            const auto version = h5::read_attr_int(file_, "format_version");
            if (version < 1 || version > trial_file_format_version)
                fail("format_version " + std::to_string(version) +
                     " is not supported (this bvc3d reads versions 1 to " + std::to_string(trial_file_format_version) +
                     (version > trial_file_format_version ? "; a newer bvc3d wrote it)" : ")"));
        }
    }

    hid_t file() const { return file_; }
    [[noreturn]] void fail(const std::string& why) const {
        throw InputError("trial file '" + path_.string() + "'" + (why.rfind(":", 0) == 0 ? why : " " + why));
    }
    // Runs `read`, turning an HDF5 error into one that names the file and `what`.
    template <class F>
    auto guarded(const std::string& what, F&& read) const {
        try {
            return read();
        } catch (const InputError& e) {
            std::string why = e.what();
            if (why.rfind("HDF5: ", 0) == 0) why.erase(0, 6);
            fail(": " + what + ": " + why);
        }
    }

    std::string text(hid_t obj, const std::string& where, const std::string& name, bool required = true) const {
        if (!h5::exists_attr(obj, name)) {
            if (required) fail(": attribute '" + where + name + "' is missing");
            return {};
        }
        if (h5::attr_class(obj, name) != H5T_STRING) fail(": attribute '" + where + name + "' is not text");
        return guarded("attribute '" + where + name + "'", [&] { return h5::read_attr_string(obj, name); });
    }
    // NaN when absent; an error when present but not a number.
    double number(hid_t obj, const std::string& where, const std::string& name) const {
        if (!h5::exists_attr(obj, name)) return NAN;
        const auto c = h5::attr_class(obj, name);
        if (c != H5T_FLOAT && c != H5T_INTEGER) fail(": attribute '" + where + name + "' is not a number");
        return guarded("attribute '" + where + name + "'", [&] { return h5::read_attr_double(obj, name); });
    }

    h5::Handle group(const std::string& name) const {
        if (!h5::exists(file_, name)) fail(": group '/" + name + "' is missing");
        return guarded("group '/" + name + "'", [&] { return h5::open_group(file_, name); });
    }

    // A float dataset of `rank` dimensions, its shape checked by the caller.
    std::vector<std::size_t> shape(hid_t loc, const std::string& where, const std::string& name,
                                   std::size_t rank) const {
        if (!h5::exists(loc, name)) fail(": dataset '" + where + name + "' is missing");
        const auto c = guarded("dataset '" + where + name + "'", [&] { return h5::dataset_class(loc, name); });
        if (c != H5T_FLOAT) fail(": dataset '" + where + name + "' does not hold floating-point numbers");
        const auto d = guarded("dataset '" + where + name + "'", [&] { return h5::dims(loc, name); });
        if (d.size() != rank)
            fail(": dataset '" + where + name + "' has " + std::to_string(d.size()) + " dimensions, not " +
                 std::to_string(rank));
        return d;
    }
    template <class T>
    std::vector<T> finite(hid_t loc, const std::string& where, const std::string& name, std::size_t per_row = 1) const {
        auto v = guarded("dataset '" + where + name + "'", [&] {
            if constexpr (std::is_same_v<T, float>) return h5::read_floats(loc, name);
            else return h5::read_doubles(loc, name);
        });
        for (std::size_t i = 0; i < v.size(); ++i)
            if (!std::isfinite(v[i]))
                fail(": dataset '" + where + name + "' holds a non-finite value (" + std::to_string(v[i]) + ") at " +
                     (per_row > 1 ? "sample " + std::to_string(i / per_row) + ", column " + std::to_string(i % per_row)
                                  : "sample " + std::to_string(i)));
        return v;
    }

private:
    std::filesystem::path path_;
    h5::Handle file_;
};

TrialIdentity read_identity(const TrialReader& r) {
    const hid_t f = r.file();
    TrialIdentity id;
    id.name = r.text(f, "/", "name");
    id.world = r.text(f, "/", "world");
    id.model = r.text(f, "/", "model");
    if (!h5::exists_attr(f, "seed")) r.fail(": attribute '/seed' is missing");
    id.seed = r.guarded("attribute '/seed'", [&] { return h5::read_attr_u64(f, "seed"); });
    id.tilt_deg = r.number(f, "/", "tilt_deg");
    id.world_source = r.text(f, "/", "world_source", false);
    id.sensor = r.text(f, "/", "sensor", false);
    id.protocol = r.text(f, "/", "protocol", false);
    id.config = r.text(f, "/", "config", false);
    id.fingerprint = r.text(f, "/", "fingerprint", false);
    id.place_weights = r.text(f, "/", "place_weights", false);
    id.place_weights_source = r.text(f, "/", "place_weights_source", false);
    id.explore_hours = r.number(f, "/", "explore_hours");
    id.sample_hours = r.number(f, "/", "sample_hours");
    // Where a replay's returns came from (as write_identity writes data_source).
    for (const char* name : {"recording", "recording_scans", "recording_poses", "recording_t0", "simulated_sensor"})
        if (h5::exists_attr(f, name)) id.data_source.emplace_back(name, r.text(f, "/", name));
    // Files from before conditions were recorded: the paper's condition, model and world.
    id.condition = h5::exists_attr(f, "condition") ? r.text(f, "/", "condition") : id.world + "_" + id.model;
    std::istringstream swept(r.text(f, "/", "swept", false));
    for (std::string line; std::getline(swept, line);) {
        const auto eq = line.find('=');
        if (eq != std::string::npos) id.swept.emplace_back(line.substr(0, eq), line.substr(eq + 1));
    }
    return id;
}

std::optional<std::vector<double>> read_extent(const TrialReader& r, hid_t metrics) {
    if (!h5::exists(metrics, "extent")) return std::nullopt;
    const auto d = r.shape(metrics, "/metrics/", "extent", 1);
    if (d[0] != 4)
        r.fail(": dataset '/metrics/extent' holds " + std::to_string(d[0]) + " values, not 4 (xmin, xmax, ymin, ymax)");
    const auto e = r.finite<double>(metrics, "/metrics/", "extent");
    if (!(e[0] < e[1] && e[2] < e[3])) r.fail(": dataset '/metrics/extent' needs xmin < xmax and ymin < ymax");
    return e;
}

}  // namespace

TrialFileData read_trial_samples(const std::filesystem::path& path) {
    auto lock = h5::hdf5_lock();
    const TrialReader r(path);
    TrialFileData d;
    static_cast<TrialIdentity&>(d) = read_identity(r);
    const auto g = r.group("metrics");
    for (const auto& name : r.guarded("group '/metrics'", [&] { return h5::attribute_names(g); }))
        d.metric_attributes.emplace_back(
            name, r.guarded("attribute '/metrics/" + name + "'", [&] { return h5::read_attr(g, name); }));
    d.extent = read_extent(r, g);
    if (h5::exists(g, "volume")) d.volume = r.finite<double>(g, "/metrics/", "volume");
    const auto s = r.group("samples");
    const auto nx = r.shape(s, "/samples/", "x", 1)[0];
    if (r.shape(s, "/samples/", "y", 1)[0] != nx) r.fail(": datasets '/samples/x' and '/samples/y' differ in length");
    const bool has_z = h5::exists(s, "z");
    if (has_z && r.shape(s, "/samples/", "z", 1)[0] != nx)
        r.fail(": dataset '/samples/z' differs in length from '/samples/x'");
    const auto rates = r.shape(s, "/samples/", "rates", 2);
    if (rates[0] != nx)
        r.fail(": dataset '/samples/rates' has " + std::to_string(rates[0]) + " rows for " + std::to_string(nx) +
               " samples");
    if (rates[1] < 1) r.fail(": dataset '/samples/rates' has no cells");
    d.x = r.finite<double>(s, "/samples/", "x");
    d.y = r.finite<double>(s, "/samples/", "y");
    if (has_z) d.z = r.finite<double>(s, "/samples/", "z");
    d.dims = format_version(r.file()) >= 2 ? 3 : 2;
    if (d.dims == 3 && !has_z) r.fail(": a 3-D trial (format version 2) without dataset '/samples/z'");
    d.rates = r.finite<float>(s, "/samples/", "rates", rates[1]);
    d.n_place = rates[1];
    return d;
}

TrialNavigation read_trial_navigation(const std::filesystem::path& path) {
    auto lock = h5::hdf5_lock();
    const TrialReader r(path);
    TrialNavigation out;
    static_cast<TrialIdentity&>(out) = read_identity(r);
    const auto g = r.group("navigation");
    const std::string where = "/navigation/";
    NavigationRecord& n = out.record;
    const double dims = r.number(g, where, "dims");
    if (dims != 2 && dims != 3) r.fail(": attribute '/navigation/dims' is not 2 or 3");
    n.dims = static_cast<int>(dims);
    n.learn_s = r.number(g, where, "learn_s");
    n.coverage = r.number(g, where, "coverage");
    for (std::string rest = r.text(g, where, "scales"); !rest.empty();) {
        const auto cut = rest.find('\n');
        n.scales.push_back(rest.substr(0, cut));
        rest = cut == std::string::npos ? "" : rest.substr(cut + 1);
    }
    // A dataset of the expected shape (0 in `shape`: any length there), as float64 or int64.
    const auto check_shape = [&](const std::string& name, std::vector<std::size_t> shape, H5T_class_t type) {
        if (!h5::exists(g, name)) r.fail(": dataset '" + where + name + "' is missing");
        if (r.guarded("dataset '" + where + name + "'", [&] { return h5::dataset_class(g, name); }) != type)
            r.fail(": dataset '" + where + name + "' does not hold " + (type == H5T_FLOAT ? "numbers" : "integers"));
        const auto d = r.guarded("dataset '" + where + name + "'", [&] { return h5::dims(g, name); });
        bool ok = d.size() == shape.size();
        for (std::size_t k = 0; ok && k < d.size(); ++k) ok = shape[k] == 0 || d[k] == shape[k];
        if (!ok) r.fail(": dataset '" + where + name + "' has the wrong shape");
        return d;
    };
    const auto reals = [&](const std::string& name, std::vector<std::size_t> shape) {
        check_shape(name, std::move(shape), H5T_FLOAT);
        return r.finite<double>(g, where, name);
    };
    const auto integers = [&](const std::string& name, std::vector<std::size_t> shape, std::int64_t lo,
                              std::int64_t hi) {
        check_shape(name, std::move(shape), H5T_INTEGER);
        const auto v = r.guarded("dataset '" + where + name + "'", [&] { return h5::read_ints(g, name); });
        for (std::size_t k = 0; k < v.size(); ++k)
            if (v[k] < lo || v[k] > hi)
                r.fail(": dataset '" + where + name + "' holds " + std::to_string(v[k]) + " at " + std::to_string(k) +
                       ", outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
        return v;
    };
    const auto d = static_cast<std::size_t>(n.dims);
    n.goals = reals("goals", {0, d});
    const std::size_t G = n.n_goals();
    const auto as_int = [](const std::vector<std::int64_t>& v) { return std::vector<int>(v.begin(), v.end()); };
    n.visits = as_int(integers("visits", {G}, 0, INT32_MAX));
    n.goal_cells = as_int(integers("goal_cells", {n.scales.size(), G}, -1, INT32_MAX));
    n.start_goal = as_int(integers("start_goal", {0}, 0, std::int64_t(G) - 1));
    const std::size_t N = n.start_goal.size();
    n.start = reals("start", {N, d});
    n.success = as_int(integers("success", {N}, 0, 1));
    n.path_m = reals("path_m", {N});
    n.shortest_m = reals("shortest_m", {N});
    n.time_s = reals("time_s", {N});
    n.path = reals("path", {0, d});
    const auto starts = integers("path_start", {N + 1}, 0, std::int64_t(n.path.size() / d));
    for (std::size_t k = 0; k + 1 < starts.size(); ++k)
        if (starts[k] > starts[k + 1]) r.fail(": dataset '/navigation/path_start' is not ascending");
    if (!starts.empty() && std::size_t(starts.back()) != n.path.size() / d)
        r.fail(": dataset '/navigation/path_start' does not end at the path's last point");
    n.path_start.assign(starts.begin(), starts.end());
    n.map_points = reals("map_points", {0, 2});
    n.map_reward = reals("map_reward", {G, n.map_points.size() / 2});
    // Written since the failure classes and walls existed (issue 46); files before them have neither.
    if (h5::exists(g, "failure"))
        n.failure = as_int(integers("failure", {N}, 0, std::int64_t(failure_class_names().size()) - 1));
    if (h5::exists(g, "walls")) n.walls = reals("walls", {0, 4});
    return out;
}

TrialRates read_trial_rates(const std::filesystem::path& path, bool bvc) {
    auto lock = h5::hdf5_lock();
    const TrialReader r(path);
    const auto s = r.group("samples");
    const std::string name = bvc ? "bvc_rates" : "rates";
    if (!h5::exists(s, name))
        r.fail(bvc ? "has no BVC rates (samples/bvc_rates): rerun it recording them" : "has no samples/rates");
    const auto n = r.shape(s, "/samples/", "x", 1)[0];
    const bool has_z = h5::exists(s, "z");
    for (const std::string k : {"y", "z", "t", "heading"})
        if ((k != "z" || has_z) && r.shape(s, "/samples/", k, 1)[0] != n)
            r.fail(": dataset '/samples/" + k + "' differs in length from '/samples/x'");
    const auto dims = r.shape(s, "/samples/", name, 2);
    if (dims[0] != n)
        r.fail(": dataset '/samples/" + name + "' has " + std::to_string(dims[0]) + " rows for " + std::to_string(n) +
               " samples");
    TrialRates out;
    out.t = r.finite<double>(s, "/samples/", "t");
    out.x = r.finite<double>(s, "/samples/", "x");
    out.y = r.finite<double>(s, "/samples/", "y");
    out.z = has_z ? r.finite<double>(s, "/samples/", "z") : std::vector<double>(n, 0.0);
    out.heading = r.finite<double>(s, "/samples/", "heading");
    out.rates = r.finite<float>(s, "/samples/", name, dims[1]);
    out.n_cells = dims[1];
    return out;
}

TrialWeights read_trial_weights(const std::filesystem::path& path) {
    auto lock = h5::hdf5_lock();
    const TrialReader r(path);
    if (!h5::exists(r.file(), "weights")) r.fail("has no weights");
    const auto dims = r.shape(r.file(), "/", "weights", 2);
    TrialWeights w;
    w.values = r.finite<float>(r.file(), "/", "weights", dims[1]);
    w.n_place = dims[0];
    w.n_bvc = dims[1];
    const h5::Handle weights(H5Dopen2(r.file(), "weights", H5P_DEFAULT), H5Dclose);
    for (auto [name, text] : {std::pair{"model", &w.model}, std::pair{"model_config", &w.model_config}}) {
        if (!h5::exists_attr(weights, name)) continue;
        if (h5::attr_class(weights, name) != H5T_STRING)
            r.fail(std::string(": attribute '/weights/") + name + "' is not text");
        *text = h5::read_attr_string(weights, name);
    }
    // Files written before /weights named its model: the root's `model` and `config` do (the configuration
    // holds the model's canonical text, which weights_model_mismatch reads the same).
    for (auto [name, text] : {std::pair{"model", &w.model}, std::pair{"config", &w.model_config}}) {
        if (!w.model_config.empty() || !text->empty() || !h5::exists_attr(r.file(), name)) continue;
        if (h5::attr_class(r.file(), name) != H5T_STRING)
            r.fail(std::string(": attribute '/") + name + "' is not text");
        *text = h5::read_attr_string(r.file(), name);
    }
    return w;
}

std::optional<NamedArray> read_trial_array(const std::filesystem::path& path, const std::string& dataset) {
    auto lock = h5::hdf5_lock();
    const TrialReader reader(path);
    const hid_t f = reader.file();
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
        case h5::Element::f64:
            a.data = h5::read_doubles(loc, rest);
            break;
        case h5::Element::f32:
            a.data = h5::read_floats(loc, rest);
            break;
        case h5::Element::integer:
            a.data = h5::read_ints(loc, rest);
            break;
        case h5::Element::other:
            throw InputError("'" + path.string() + "': dataset '" + dataset + "' holds neither numbers nor integers");
    }
    return a;
}

TrialSummaryRow read_trial_summary(const std::filesystem::path& path, const std::vector<std::string>& metric_names,
                                   const std::vector<std::string>& parameter_names) {
    auto lock = h5::hdf5_lock();
    const TrialReader r(path);
    TrialSummaryRow row;
    static_cast<TrialIdentity&>(row) = read_identity(r);
    const auto g = r.group("metrics");
    for (const auto& name : metric_names) row.metrics.emplace_back(name, r.number(g, "/metrics/", name));
    for (const auto& name : parameter_names) {
        std::string value = "(not recorded)";
        if (h5::exists_attr(g, name))
            value =
                params::to_text(r.guarded("attribute '/metrics/" + name + "'", [&] { return h5::read_attr(g, name); }));
        row.parameters.emplace_back(name, value);
    }
    std::string extent = "data";
    if (const auto e = read_extent(r, g)) extent = params::to_text(*e);
    row.parameters.emplace_back("extent", extent);
    return row;
}

}  // namespace bvc3d

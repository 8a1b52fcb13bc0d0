// Whole trials: run_trial, through the same pipeline as `bvc3d run`.
#include "bindings.hpp"

#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/analysis/metrics.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/experiment/pipeline.hpp"

namespace bvc3d::py {

namespace {

// A trajectory from a file path or from a mapping of arrays t, x, y, heading (and optionally z).
std::shared_ptr<const AgentSpec> trajectory_of(const pyb::object& obj) {
    if (pyb::isinstance<pyb::str>(obj) || pyb::hasattr(obj, "__fspath__"))
        return std::make_shared<TrajectorySpec>(TrajectorySpec::from_file(pyb::str(obj).cast<std::string>()));
    if (!pyb::isinstance<pyb::dict>(obj))
        throw InputError("trajectory must be a file path or a dict of arrays t, x, y, heading (and optionally z)");
    const auto d = obj.cast<pyb::dict>();
    auto column = [&](const char* key) {
        if (!d.contains(key)) return std::vector<double>{};
        const auto a = real_array(d[key], std::string("trajectory['") + key + "']");
        if (a.ndim() > 1) throw InputError(std::string("trajectory['") + key + "'] must be 1-D");
        return std::vector<double>(a.data(), a.data() + a.size());
    };
    for (const char* key : {"t", "x", "y", "heading"})
        if (!d.contains(key)) throw InputError(std::string("trajectory: the dict lacks '") + key + "'");
    return std::make_shared<TrajectorySpec>(
        trajectory_steps(column("t"), column("x"), column("y"), column("z"), column("heading"), "trajectory arrays"),
        "arrays");
}

TrialConfig trial_of(const std::string& model, const std::string& world, std::optional<double> tilt_deg,
                     const pyb::object& seed, const pyb::kwargs& kwargs) {
    TrialConfig t;
    t.model = config::resolve_model(model);
    t.world = WorldSpec{world, tilt_deg, t.world.lean};
    t.seed = seed_of(seed, "seed");
    if (kwargs.contains("trajectory") && !kwargs["trajectory"].is_none()) t.agent = trajectory_of(kwargs["trajectory"]);
    apply_kwargs(t.protocol, Protocol::table(), kwargs, {"trajectory", "protocol"});
    if (kwargs.contains("protocol")) t.protocol.kind = parse_protocol(pyb::str(kwargs["protocol"]));  // = kind
    t.validate();
    return t;
}

pyb::dict outcome_to_dict(const TrialConfig& t, const GroupOutcome& done) {
    const auto& r = done.result;
    const auto n = static_cast<pyb::ssize_t>(r.t.size());
    const auto& rec = r.models[0];
    pyb::dict out;
    out["t"] = to_numpy(r.t.data(), {n});
    out["x"] = to_numpy(r.x.data(), {n});
    out["y"] = to_numpy(r.y.data(), {n});
    out["z"] = to_numpy(r.z.data(), {n});
    out["heading"] = to_numpy(r.heading.data(), {n});
    out["rates"] = to_numpy(rec.rates.data(), {n, rec.n_place});
    if (t.protocol.record_bvc) out["bvc_rates"] = to_numpy(rec.bvc.data(), {n, rec.n_bvc});
    out["weights"] = to_numpy(rec.weights.data(), {rec.n_place, rec.n_bvc});
    pyb::dict scalars;
    for (const auto& [name, v] : analysis::scalar_metrics(done.trials[0].metrics)) scalars[name.c_str()] = v;
    out["metrics"] = scalars;
    out["name"] = t.name();
    return out;
}

}  // namespace

void bind_experiment(pyb::module_& m) {
    m.def(
        "run_trial",
        [](const std::string& model, const std::string& world, std::optional<double> tilt_deg, const pyb::object& seed,
           const pyb::kwargs& kwargs) {
            const TrialConfig t = trial_of(model, world, tilt_deg, seed, kwargs);
            const GroupOutcome done = interruptible([&](const std::atomic<bool>& stop) {
                RunControl control;
                control.stop = &stop;  // Ctrl-C: KeyboardInterrupt within a fraction of a second
                return run_and_analyze({t}, control);
            });
            return outcome_to_dict(t, done);
        },
        pyb::arg("model") = TrialConfig{}.model.name, pyb::arg("world") = WorldSpec{}.source,
        pyb::arg("tilt_deg") = pyb::none(), pyb::arg("seed") = 0,
        (R"doc(One trial at full speed, as `bvc3d run` does it, returned as numpy arrays: t, x, y, z, heading
(samples,), rates (samples, n_place) float32, weights (n_place, n_bvc), bvc_rates if recorded, and
metrics (dict of the scalar metrics). model: a preset or model YAML; world: a preset or world YAML;
tilt_deg: for world="cross"; trajectory: a file path or a dict of arrays t, x, y, heading[, z] to
follow instead of the random walk. Protocol keywords and their defaults:
)doc" + describe(Protocol::table(), Protocol{}))
            .c_str());
    pyb::list metrics;
    for (const auto& mt : analysis::metric_table()) {
        pyb::dict d;
        d["name"] = mt.name;
        d["heading"] = mt.heading;
        d["label"] = mt.label;
        d["title"] = mt.title;
        d["digits"] = mt.digits;
        metrics.append(d);
    }
    m.attr("metric_table") = metrics;
}

}  // namespace bvc3d::py

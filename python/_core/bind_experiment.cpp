// Whole trials: run_trial, through the same pipeline as `bvc3d run`.
#include "bindings.hpp"

#include "bvc3d/agent/flying_walk.hpp"
#include "bvc3d/agent/trajectory.hpp"
#include "bvc3d/analysis/metrics.hpp"
#include "bvc3d/config/agent_kinds.hpp"
#include "bvc3d/config/authors.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/protocols.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/experiment/elevation_chooser.hpp"
#include "bvc3d/experiment/pipeline.hpp"
#include "bvc3d/recording/recording.hpp"

namespace bvc3d::py {

std::vector<std::string> trajectory_keywords() {
    std::vector<std::string> keys;
    for (const auto& f : TrajectoryParams::table().fields()) keys.push_back(f.key);
    return keys;
}

std::shared_ptr<const TrajectorySpec> trajectory_of(const pyb::object& obj, const pyb::kwargs& kwargs) {
    TrajectoryParams params;
    pyb::kwargs given;
    for (const auto& key : trajectory_keywords())
        if (kwargs.contains(key.c_str())) given[key.c_str()] = kwargs[key.c_str()];
    apply_kwargs(params, TrajectoryParams::table(), given);
    if (pyb::isinstance<pyb::str>(obj) || pyb::hasattr(obj, "__fspath__"))
        return std::make_shared<TrajectorySpec>(TrajectorySpec::from_file(pyb::str(obj).cast<std::string>(), params));
    if (!pyb::isinstance<pyb::dict>(obj))
        throw InputError(
            "trajectory must be a file path or a dict of arrays t, x, y, heading (and optionally z, pitch, roll)");
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
        trajectory_steps(column("t"), column("x"), column("y"), column("z"), column("heading"), "trajectory arrays",
                         column("pitch"), column("roll")),
        "arrays", params);
}

namespace {

// A keyword that must be a dict of a table's keys (flight=, analysis=, bvc=, place=).
pyb::kwargs dict_argument(const pyb::object& obj, const std::string& key, const std::string& example) {
    if (!pyb::isinstance<pyb::dict>(obj))
        throw InputError("run_trial: " + key + "= must be a dict of keywords, e.g. " + key + "=dict(" + example + ")");
    return obj.cast<pyb::kwargs>();
}

// A text argument (a name or a path): anything else is refused naming the argument.
std::string text_argument(const pyb::object& obj, const std::string& key, const std::string& what) {
    if (pyb::isinstance<pyb::str>(obj) || pyb::hasattr(obj, "__fspath__")) return pyb::str(obj).cast<std::string>();
    throw InputError("run_trial: " + key + "= must be " + what + ", not " + type_name(obj));
}

// The keywords run_trial takes besides the protocol's, and their hint for keys of other places.
const std::vector<std::string> trial_keywords = {"trajectory", "protocol", "agent", "flight",       "authors_choices",
                                                 "analysis",   "bvc",      "place", "step_per_row", "model_dt"};

void check_trial_keywords(const pyb::kwargs& kwargs) {
    for (const auto& [k, v] : kwargs) {
        const std::string key = pyb::str(k);
        if (Protocol::table().find(key) ||
            std::find(trial_keywords.begin(), trial_keywords.end(), key) != trial_keywords.end())
            continue;
        if (analysis::AnalysisParams::table().find(key))
            throw InputError("run_trial: '" + key + "' is an analysis parameter: give analysis=dict(" + key + "=...)");
        if (BvcParams::table().find(key) || PlaceParams::table().find(key))
            throw InputError("run_trial: '" + key + "' is a model parameter: give bvc=dict(" + key +
                             "=...) or place=dict(" + key + "=...) (see help(bvc3d.BoundaryVectorLayer), " +
                             "help(bvc3d.PlaceCellNetwork))");
        if (key == "sensor" || key == "robot")
            throw InputError("run_trial: '" + key + "' is not a keyword of run_trial: a model's sensor is set in a " +
                             "model YAML (model=FILE; `bvc3d config --model 3d-0.2` prints one to start from), the " +
                             "robot's in a trial YAML (`bvc3d run --config FILE`)");
        std::string accepted = "model, world, tilt_deg, seed";
        for (const auto& t : trial_keywords) accepted += ", " + t;
        for (const auto& f : Protocol::table().fields()) accepted += ", " + f.key;
        throw InputError("run_trial: unknown argument '" + key + "' (accepted: " + accepted + ")");
    }
}

TrialConfig trial_of(const pyb::object& model, const pyb::object& world, const pyb::object& tilt_deg,
                     const pyb::object& seed, const pyb::kwargs& kwargs) {
    check_trial_keywords(kwargs);
    TrialConfig t;
    t.model = config::resolve_model(text_argument(model, "model", "a model preset name or a model YAML path"));
    const bool model_changed = kwargs.contains("bvc") || kwargs.contains("place");
    if (kwargs.contains("bvc"))
        apply_kwargs(t.model.bvc, BvcParams::table(), dict_argument(kwargs["bvc"], "bvc", "n_per_axis=12"));
    if (kwargs.contains("place"))
        apply_kwargs(t.model.place, PlaceParams::table(), dict_argument(kwargs["place"], "place", "n_place=100"));
    if (model_changed) {
        t.model.name += "-custom";  // as an inline model YAML that changes its base is named
        t.model.validate();
    }
    std::optional<double> tilt;
    if (!tilt_deg.is_none()) tilt = std::get<double>(to_value(tilt_deg, params::Kind::real, "tilt_deg"));
    t.world = world_source_of(world, "run_trial: world");
    if (tilt && pyb::isinstance<World>(world))
        throw InputError("run_trial: tilt_deg goes with a world's name; the World given has its own tilt");
    if (tilt) t.world.tilt_deg = tilt;
    t.seed = seed_of(seed, "seed");
    const auto agent = kwargs.contains("agent") ? agent_by_name(pyb::str(kwargs["agent"])) : nullptr;
    const bool flight = agent && dynamic_cast<const FlightSpec*>(agent.get());
    if (kwargs.contains("flight") && !flight)
        throw InputError("flight= (the flying agent's parameters) needs agent='flight'");
    if (agent) {
        t.set_agent(agent);
        // The protocol of the agent's kind (docs/flying.md: 8 h + 8 h when flying) unless the keywords say otherwise.
        t.protocol = protocol_preset(agent_kind_of(*agent).protocol);
    }
    if (flight && kwargs.contains("flight") && !kwargs["flight"].is_none()) {
        FlightParams params;
        apply_kwargs(params, FlightParams::table(), dict_argument(kwargs["flight"], "flight", "speed=0.5"));
        t.set_agent(std::make_shared<FlightSpec>(params));
    }
    if (kwargs.contains("trajectory") && !kwargs["trajectory"].is_none()) {
        if (agent) throw InputError("give agent= or trajectory=, not both");
        t.set_agent(trajectory_of(kwargs["trajectory"], kwargs));
    } else {
        for (const auto& key : trajectory_keywords())
            if (kwargs.contains(key.c_str()))
                throw InputError("run_trial: " + key + "= goes with trajectory= (how a given path steps the model)");
    }
    if (kwargs.contains("authors_choices")) {
        const auto choices = kwargs["authors_choices"];
        if (pyb::isinstance<pyb::str>(choices) || !pyb::isinstance<pyb::sequence>(choices))
            throw InputError("run_trial: authors_choices= must be a list of names, e.g. [\"all\"]");
        std::vector<std::string> names;
        for (const auto& c : choices)
            names.push_back(
                text_argument(pyb::reinterpret_borrow<pyb::object>(c), "authors_choices", "a list of names"));
        apply_authors_choices(t, names);
    }
    apply_kwargs(t.protocol, Protocol::table(), kwargs, trial_keywords);
    if (kwargs.contains("protocol")) t.protocol.kind = parse_protocol(pyb::str(kwargs["protocol"]));  // = kind
    // Analysis keywords last: they apply over the agent's defaults (min_samples 10 in 3-D) and the authors' choices.
    if (kwargs.contains("analysis"))
        apply_kwargs(t.analysis, analysis::AnalysisParams::table(),
                     dict_argument(kwargs["analysis"], "analysis", "eps=0.1, d_th=0.2"));
    t.validate();
    t.agent->check_world(t.world.resolve());
    return t;
}

pyb::dict outcome_to_dict(const TrialConfig& t, const GroupOutcome& done) {
    pyb::dict out = samples_to_dict(done.result, t.protocol.record_bvc);
    pyb::dict scalars;
    if (!t.place_cells_untrained())  // else the metrics of random weights: left out, as in trial files
        for (const auto& [name, v] : analysis::scalar_metrics(done.trials[0].metrics)) scalars[name.c_str()] = v;
    out["metrics"] = scalars;
    out["place_weights"] = t.place_weights();
    out["name"] = t.name();
    // Every other population: its recorded rates and, when analysed, its metrics (a multiscale model's scales and
    // their fusion, place-fused, which has metrics only).
    pyb::dict populations;
    const auto n = static_cast<pyb::ssize_t>(done.result.t.size());
    for (const PopulationRecord& p : done.result.models[0].populations) {
        pyb::dict d;
        if (p.recorded) d["rates"] = to_numpy(p.rates.data(), {n, static_cast<pyb::ssize_t>(p.cells)});
        populations[p.name.c_str()] = d;
    }
    for (const auto& [name, analysed] : done.trials[0].populations) {
        pyb::dict metrics;
        for (const auto& [key, v] : analysis::scalar_metrics(analysed.metrics)) metrics[key.c_str()] = v;
        if (!populations.contains(name.c_str())) populations[name.c_str()] = pyb::dict();
        populations[name.c_str()].cast<pyb::dict>()["metrics"] = metrics;
    }
    out["populations"] = populations;
    return out;
}

}  // namespace

pyb::dict samples_to_dict(const GroupResult& r, bool with_bvc) {
    const auto n = static_cast<pyb::ssize_t>(r.t.size());
    const auto& rec = r.models[0];
    pyb::dict out;
    out["t"] = to_numpy(r.t.data(), {n});
    out["x"] = to_numpy(r.x.data(), {n});
    out["y"] = to_numpy(r.y.data(), {n});
    out["z"] = to_numpy(r.z.data(), {n});
    out["heading"] = to_numpy(r.heading.data(), {n});
    out["rates"] = to_numpy(rec.rates.data(), {n, rec.n_place});
    if (with_bvc) out["bvc_rates"] = to_numpy(rec.bvc.data(), {n, rec.n_bvc});
    out["weights"] = to_numpy(rec.weights.data(), {rec.n_place, rec.n_bvc});
    return out;
}

namespace {

// The chooser's result as bvc3d.choose_elevations returns it.
pyb::dict choice_to_dict(const ElevationChoice& c) {
    pyb::list candidates;
    for (const auto& s : c.candidates)
        candidates.append(pyb::dict(pyb::arg("elevations") = s.elevations, pyb::arg("n_per_axis") = s.n_per_axis,
                                    pyb::arg("round") = s.round, pyb::arg("msai") = s.msai,
                                    pyb::arg("frac_multimodal") = s.frac_multimodal,
                                    pyb::arg("bvc_msai") = s.bvc_msai));
    return pyb::dict(pyb::arg("elevations") = c.chosen.elevations, pyb::arg("n_per_axis") = c.chosen.n_per_axis,
                     pyb::arg("msai") = c.chosen.msai, pyb::arg("candidates") = candidates,
                     pyb::arg("walk_steps") = c.walk_steps, pyb::arg("model_yaml") = config::model_to_yaml(c.model));
}

}  // namespace

void bind_experiment(pyb::module_& m) {
    m.def(
        "run_trial",
        [](const pyb::object& model, const pyb::object& world, const pyb::object& tilt_deg, const pyb::object& seed,
           const pyb::kwargs& kwargs) {
            const TrialConfig t = trial_of(model, world, tilt_deg, seed, kwargs);
            std::vector<std::string> warnings;  // collected on the worker, raised as Python warnings here
            const GroupOutcome done = interruptible([&](const std::atomic<bool>& stop) {
                RunControl control;
                control.stop = &stop;  // Ctrl-C: KeyboardInterrupt within a fraction of a second
                control.warn = [&](const std::string& message) { warnings.push_back(message); };
                return run_and_analyze({t}, control);
            });
            for (const auto& w : warnings)
                if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw pyb::error_already_set();
            return outcome_to_dict(t, done);
        },
        pyb::arg("model") = TrialConfig{}.model.name, pyb::arg("world") = WorldSpec{}.source,
        pyb::arg("tilt_deg") = pyb::none(), pyb::arg("seed") = 0,
        (R"doc(One trial at full speed, as `bvc3d run` does it, returned as numpy arrays: t, x, y, z, heading
(samples,), rates (samples, n_place) float32, weights (n_place, n_bvc), bvc_rates if recorded, and
metrics (dict of the scalar metrics). model: a preset or model YAML; world: a preset, a world file or a World
made from one (World.preset, World.from_yaml: the trial file records where it came from);
tilt_deg: for world="cross" or "cross-webots"; trajectory: a file path or a dict of arrays t, x, y, heading[, z,
pitch, roll] to follow instead of the random walk, its rows resampled to model steps model_dt=0.288 s apart
(positions linearly, headings along the shorter arc) unless they are at that step already (step_per_row=True:
one model step per row); agent: the agent by name, )doc" +
         agent_names_text() + R"doc(; agent="flight" is the flying agent (docs/flying.md: a fly-* model,
a world with a flight volume, )doc" +
         protocol_hours_text(protocol_preset(agent_kind("flight").protocol)) +
         R"doc( h unless given, 3-D metrics), with flight=dict(...) for its parameters (see
flying_walk); analysis=dict(...): analysis parameters (the keys of a trial YAML's analysis:, see
`bvc3d config`; eps and d_th are metres, for the paper's 10 m arena: in a much smaller one set them
to its scale, a warning says when they cannot work); bvc=dict(...), place=dict(...): the model's
BVC and place-cell parameters over its preset (help(bvc3d.BoundaryVectorLayer),
help(bvc3d.PlaceCellNetwork)); authors_choices: a list of the authors' choices to switch on (as `bvc3d paper
--authors-choices`; ["all"] for all of them; protocol keywords still apply after them).
Protocol keywords and their defaults:
)doc" + describe(Protocol::table(), Protocol{}))
            .c_str());
    m.def(
        "choose_elevations",
        [](const pyb::object& world, std::optional<double> tilt_deg, const std::string& agent_name,
           const std::optional<std::string>& sensor, std::uint64_t seed,
           std::optional<std::vector<std::vector<double>>> sets, int jobs,
           const std::shared_ptr<recording::Recording>& recorded, const pyb::kwargs& kwargs) {
            if (recorded && (!world.is_none() || tilt_deg || agent_name != "ground"))
                throw InputError("a recording is its own walk: give recording or world (and agent), not both");
            const auto agent = agent_by_name(agent_name);
            const ChooserDefaults defaults = chooser_defaults(*agent);
            const auto preprocess_keys = RecordedReturnParams::table().keys();
            const auto listed = [](const std::vector<std::string>& keys) {
                std::string out;
                for (const auto& k : keys) out += (out.empty() ? "" : ", ") + k;
                return out;
            };
            if (recorded)
                for (const auto& [k, v] : kwargs) {
                    const std::string key = pyb::str(k);
                    if (!ChooserParams::table().find(key) && !RecordedReturnParams::table().find(key))
                        throw InputError("choose_elevations: unknown argument '" + key +
                                         "' (accepted: " + listed(ChooserParams::table().keys()) +
                                         ", and on a recording " + listed(preprocess_keys) + ")");
                }
            ChooserParams p;
            apply_kwargs(p, ChooserParams::table(), kwargs, recorded ? preprocess_keys : std::vector<std::string>{});
            if (defaults.symmetric_range && !kwargs.contains("elevation_min")) p.elevation_min = -p.elevation_max;
            p.seed = seed;
            p.jobs = jobs;
            ModelSpec base = model_preset(defaults.model);
            base.sensor = config::resolve_sensor(sensor.value_or(defaults.sensor));
            const auto analysis = analysis::AnalysisParams::defaults(agent->dims());
            std::optional<ReplaySource> source;
            // A World given is used as it is; a name or a path is read on the worker (a building takes seconds).
            std::shared_ptr<const World> given;
            std::string world_name = WorldSpec{}.source;
            if (pyb::isinstance<World>(world)) {
                if (tilt_deg) throw InputError("choose_elevations: tilt_deg goes with a world's name, not a World");
                given = world_of(world, "choose_elevations: world");
            } else if (!world.is_none()) {
                world_name = world_source_of(world, "choose_elevations: world").source;
            }
            if (recorded) {
                RecordedReturnParams preprocess;
                apply_kwargs(preprocess, RecordedReturnParams::table(), kwargs, ChooserParams::table().keys());
                source = recorded_source(recorded, preprocess);
            }
            const ElevationChoice c = interruptible([&](const std::atomic<bool>& stop) {
                p.stop = &stop;  // Ctrl-C: KeyboardInterrupt within a fraction of a second
                if (source)
                    return choose_elevations_on(*source, base, p, analysis,
                                                sets.value_or(std::vector<std::vector<double>>{}));
                const auto w =
                    given ? given : std::make_shared<const World>(config::resolve_world(world_name, tilt_deg));
                agent->check_world(w->description());
                return sets ? choose_from_sets(*w, base, *agent, *sets, p, analysis)
                            : choose_elevations(*w, base, *agent, p, analysis);
            });
            return choice_to_dict(c);
        },
        pyb::arg("world") = pyb::none(), pyb::arg("tilt_deg") = pyb::none(), pyb::arg("agent") = "ground",
        pyb::arg("sensor") = pyb::none(), pyb::arg("seed") = 0, pyb::arg("sets") = pyb::none(),
        pyb::arg("jobs") = ChooserParams{}.jobs, pyb::arg("recording") = pyb::none(),
        (R"doc(The agent's choice of BVC elevations from its own exploratory walk, as `bvc3d choose-elevations`
does it: the criterion (MSAI of the place-cell network on the walk, lower is better) of each
candidate set of the greedy search, or of the given `sets` (lists of elevations, rad). Returns a
dict: elevations, n_per_axis, msai (of the chosen set), candidates (a list of dicts: elevations,
n_per_axis, round, msai, frac_multimodal, bvc_msai: the same MSAI over the BVC population's
rate maps, shown, not used), walk_steps, model_yaml. world: a preset, a world file or a World (default:
the cross arena); agent: "ground" (the paper's robot, sensor "spherical", 3d-0.2's cells) or "flying"
(the flying agent, sensor "spherical-full", fly-5l's cells, candidates from -elevation_max unless
elevation_min is given; 3-D analysis); sensor: another sensor preset or YAML; seed: the walk's (on a
recording: the initial weights'); jobs: threads (0: every core). recording: a Recording instead of a
world: its poses are the walk and its scans the returns (the ground robot's cells; preprocessing
keywords as Recording.replay, e.g. min_range, max_range). Keywords and their defaults (elevation_min:
on the ground):
)doc" + describe(ChooserParams::table(), ChooserParams{}))
            .c_str());
    pyb::list metrics;
    for (const auto& mt : analysis::metric_table()) {
        pyb::dict d;
        d["name"] = mt.name;
        d["heading"] = mt.heading;
        d["label"] = mt.label;
        d["title"] = mt.title;
        d["digits"] = mt.digits;
        d["dims"] = mt.dims;  // 0: every trial; 3: flying agents' (3-D) trials only
        metrics.append(d);
    }
    m.attr("metric_table") = metrics;
}

}  // namespace bvc3d::py

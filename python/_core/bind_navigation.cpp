// Navigation to goals (docs/navigation.md): the HD-conditioned adjacency, replay and the choice of direction by
// hand, the shortest path of SPEC §17, and a whole navigation run.
#include "bindings.hpp"

#include <cmath>

#include "bvc3d/agent/body_collider.hpp"
#include "bvc3d/agent/shortest_path.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/experiment/navigation.hpp"
#include "bvc3d/navigation/failure_class.hpp"
#include "bvc3d/navigation/replay.hpp"
#include "bvc3d/navigation/rollouts.hpp"
#include "bvc3d/navigation/scale_mix.hpp"

namespace bvc3d::py {

namespace {

std::vector<double> vector_of(const pyb::handle& obj, const std::string& name, std::size_t n) {
    const auto a = real_array(obj, name);
    if (a.ndim() != 1 || std::size_t(a.shape(0)) != n)
        throw InputError(name + " must be a 1-D array of " + std::to_string(n) + " values");
    for (std::size_t i = 0; i < n; ++i)
        if (!std::isfinite(a.data()[i])) throw InputError(name + "[" + std::to_string(i) + "] is not finite");
    return {a.data(), a.data() + n};
}

Vec2 point_of(const pyb::handle& obj, const std::string& name) {
    const auto v = vector_of(obj, name, 2);
    return {v[0], v[1]};
}

RewardParams reward_of(const pyb::kwargs& kwargs) {
    RewardParams p;
    apply_kwargs(p, RewardParams::table(), kwargs);
    return p;
}

// A dict keyword (a YAML file's section: navigation=, adjacency=, reward=, flight=) as the keywords of its table.
pyb::kwargs section_of(const std::string& key, const pyb::handle& v) {
    if (!pyb::isinstance<pyb::dict>(v))
        throw InputError(key + " must be a dict of the parameters of a navigation YAML's `" + key + ":` section");
    return pyb::kwargs(pyb::reinterpret_borrow<pyb::dict>(v));
}

// Keywords as a navigation YAML has them (docs/navigation.md#a-yaml-file): its sections as dicts (navigation=,
// adjacency=, reward=, flight=), policy= and the policy's own section (e.g. authors=dict(...)); and, flat, the keys
// of the navigation, reward and adjacency tables, each to whichever table names it.
void apply_navigation(NavigationSpec& s, const pyb::kwargs& kwargs) {
    pyb::kwargs a, b, c;
    std::string policy = default_policy_kind().name;
    std::optional<std::pair<std::string, std::string>> policy_section;  // its key and the dict as JSON (YAML)
    const auto sections = config::policy_yaml_keys();
    for (const auto& [k, v] : kwargs) {
        const std::string key = pyb::str(k);
        if (key == "flight") apply_kwargs(s.space.flight, FlightParams::table(), section_of(key, v));
        else if (key == "navigation") apply_kwargs(s.space.nav, NavigationParams::table(), section_of(key, v));
        else if (key == "adjacency") apply_kwargs(s.adjacency, AdjacencyParams::table(), section_of(key, v));
        else if (key == "reward") apply_kwargs(s.reward, RewardParams::table(), section_of(key, v));
        else if (key == "policy") policy = pyb::str(v);
        else if (std::find(sections.begin(), sections.end(), key) != sections.end()) {
            section_of(key, v);
            policy_section = {key, pyb::str(pyb::module_::import("json").attr("dumps")(v))};
        } else if (RewardParams::table().find(key)) b[k] = v;
        else if (AdjacencyParams::table().find(key) && !NavigationParams::table().find(key)) c[k] = v;
        else a[k] = v;
    }
    apply_kwargs(s.space.nav, NavigationParams::table(), a);
    apply_kwargs(s.reward, RewardParams::table(), b);
    apply_kwargs(s.adjacency, AdjacencyParams::table(), c);
    s.space.n_hd = s.adjacency.n_hd;
    if (policy_section) {
        const auto& [key, json] = *policy_section;
        if (policy_kind(policy).section != key)
            throw InputError(key + "= gives the parameters of another policy than policy='" + policy + "'");
        const auto view = config::YamlView::load_string(json, key + "=");
        s.policy = config::policy_named(policy, &view);
    } else {
        s.policy = config::policy_named(policy);
    }
}

}  // namespace

void bind_navigation(pyb::module_& m) {
    auto cls = pyb::class_<HdAdjacency>(m, "HdAdjacency",
                                        (R"doc(
The HD-conditioned adjacency of place cells (SPEC §16, docs/navigation.md): one transition matrix per HD cell.
HdAdjacency(n_place, **params); params and their defaults:
)doc" + describe(AdjacencyParams::table(), AdjacencyParams{}))
                                            .c_str());
    cls.def(pyb::init([](int n_place, const pyb::kwargs& kwargs) {
                AdjacencyParams p;
                apply_kwargs(p, AdjacencyParams::table(), kwargs);
                return HdAdjacency(n_place, p);
            }),
            pyb::arg("n_place"))
        .def(
            "learn",
            [](HdAdjacency& a, const pyb::object& place, const pyb::object& hd, bool bumped) {
                a.learn(vector_of(place, "place", std::size_t(a.n_place())), vector_of(hd, "hd", std::size_t(a.n_hd())),
                        bumped);
            },
            pyb::arg("place"), pyb::arg("hd"), pyb::arg("bumped") = false,
            "One learning step: place-cell rates (n_place,), HD rates (n_hd,)")
        .def_property(
            "weights",
            [](const HdAdjacency& a) {
                const int n = a.n_place(), h = a.n_hd();
                std::vector<double> w(std::size_t(h) * n * n);
                for (int k = 0; k < h; ++k)
                    for (int i = 0; i < n; ++i)
                        for (int j = 0; j < n; ++j) w[(std::size_t(k) * n + i) * n + j] = a.weight(k, i, j);
                return to_numpy(w.data(), {h, n, n});
            },
            [](HdAdjacency& a, const pyb::object& obj) {
                const auto w = real_array_f32(obj, "weights");
                a.set_weights({w.data(), std::size_t(w.size())});
            },
            "W_rec as an (n_hd, n_place, n_place) array; W_rec[k, i, j] > 0: i follows j heading along k")
        .def_property_readonly("place_trace",
                               [](const HdAdjacency& a) { return to_numpy(a.place_trace().data(), {a.n_place()}); })
        .def_property_readonly("hd_trace",
                               [](const HdAdjacency& a) { return to_numpy(a.hd_trace().data(), {a.n_hd()}); })
        .def(
            "replay",
            [](const HdAdjacency& a, int goal_cell, const pyb::kwargs& kwargs) {
                const auto w = replay(a, goal_cell, reward_of(kwargs));
                return to_numpy(w.data(), {a.n_place()});
            },
            pyb::arg("goal_cell"),
            ("The reward cell's weights after replay from place cell goal_cell (SPEC §17). Keywords:\n" +
             describe(RewardParams::table(), RewardParams{}))
                .c_str())
        .def(
            "direction_returns",
            [](const HdAdjacency& a, const pyb::object& w, const pyb::object& v, const pyb::kwargs& kwargs) {
                const auto n = std::size_t(a.n_place());
                const auto r = direction_returns(a, vector_of(w, "w", n), vector_of(v, "v", n), reward_of(kwargs));
                return to_numpy(r.data(), {a.n_hd()});
            },
            pyb::arg("w"), pyb::arg("v"), "Each HD direction's rollout return R_k from place-cell rates v (SPEC §17)");
    m.def(
        "combine_scales",
        [](const pyb::object& returns, const pyb::object& allowed, const pyb::object& scores,
           const pyb::kwargs& kwargs) {
            const auto r = real_array(returns, "returns");
            if (r.ndim() != 2 || r.shape(0) < 1 || r.shape(1) < 1)
                throw InputError("returns must be a 2-D array: scales × directions");
            const auto n_scales = std::size_t(r.shape(0)), n_dir = std::size_t(r.shape(1));
            std::vector<std::vector<double>> per_scale;
            for (std::size_t s = 0; s < n_scales; ++s) {
                per_scale.emplace_back(r.data() + s * n_dir, r.data() + (s + 1) * n_dir);
                for (double x : per_scale.back())
                    if (!std::isfinite(x)) throw InputError("returns are not all finite");
            }
            const auto open = vector_of(allowed, "allowed", n_dir);
            std::vector<double> carried =
                scores.is_none() ? std::vector<double>{} : vector_of(scores, "scores", n_scales);
            const auto prob =
                combine_scales(per_scale, std::vector<char>(open.begin(), open.end()), reward_of(kwargs), carried);
            return pyb::make_tuple(to_numpy(prob.data(), {pyb::ssize_t(n_dir)}),
                                   to_numpy(carried.data(), {pyb::ssize_t(n_scales)}));
        },
        pyb::arg("returns"), pyb::arg("allowed"), pyb::arg("scores") = pyb::none(),
        "The choice's probabilities over directions from each scale's returns (scales × directions; allowed: 1 where "
        "a direction is offered) and the scales' smoothed scores after it (pass them back as scores at the next "
        "decision; None at a start's first). SPEC §17, docs/navigation.md#multiscale. Keywords: the reward "
        "parameters (beta, scale_beta, scale_smoothing).");
    m.def(
        "reward_readout",
        [](const pyb::object& w, const pyb::object& v) {
            const auto wv = real_array(w, "w");
            const auto n = std::size_t(wv.size());
            return reward(vector_of(w, "w", n), vector_of(v, "v", n));
        },
        pyb::arg("w"), pyb::arg("v"), "r = w·v / max(|v|₁, 1e-4)");
    m.def(
        "shortest_path",
        [](const pyb::object& world, const pyb::object& start, const pyb::object& goal, double cell, double inflate) {
            const auto w = world_of(world, "shortest_path: world");
            const RobotParams robot;
            const BodyCollider body(w->description(), robot.radius, robot.height);
            const FreeSpaceGrid grid(body, cell);
            const auto p = shortest_path(grid, point_of(start, "start"), point_of(goal, "goal"), inflate);
            pyb::dict d;
            d["found"] = p.found;
            d["length"] = p.length;
            std::vector<double> xy;
            for (const Vec2& q : p.points) xy.push_back(q.x()), xy.push_back(q.y());
            d["points"] = to_numpy(xy.data(), {pyb::ssize_t(p.points.size()), 2});
            return d;
        },
        pyb::arg("world"), pyb::arg("start"), pyb::arg("goal"), pyb::arg("cell") = 0.1, pyb::arg("inflate") = 0.5,
        "SPEC §17's shortest path (A* on a grid of `cell` m, obstacles inflated by `inflate` m): dict found, length "
        "(m), points (N, 2)");
    m.def(
        "navigate",
        [](const pyb::object& world, const pyb::object& goals, const std::string& model, const pyb::object& seed,
           const pyb::kwargs& kwargs) {
            const auto w = world_of(world, "navigate: world");
            NavigationSpec s;
            const ModelSpec model_spec = config::resolve_model(model);
            const auto g = real_array(goals, "goals");
            if (g.ndim() != 2 || (g.shape(1) != 2 && g.shape(1) != 3))
                throw InputError("goals must be an (N, 2) array of x, y (on the floor) or (N, 3) of x, y, z (flying)");
            for (pyb::ssize_t i = 0; i < g.shape(0); ++i)
                s.space.goals.push_back(g.shape(1) == 3 ? NavigationGoal(g.at(i, 0), g.at(i, 1), g.at(i, 2))
                                                        : NavigationGoal(g.at(i, 0), g.at(i, 1)));
            apply_navigation(s, kwargs);
            const std::uint64_t seed_value = seed_of(seed, "seed");  // with the GIL, before the work lets it go
            const NavigationRecord run = interruptible(
                [&](const std::atomic<bool>& stop) { return navigate(*w, model_spec, s, seed_value, &stop); });
            const int dims = run.dims;
            const auto n = pyb::ssize_t(run.n_starts());
            std::vector<double> gx, gy, gz, sx, sy, sz;
            pyb::list paths;
            for (pyb::ssize_t i = 0; i < n; ++i) {
                const auto k = std::size_t(i), goal = std::size_t(run.start_goal[k]) * std::size_t(dims);
                gx.push_back(run.goals[goal]), gy.push_back(run.goals[goal + 1]);
                gz.push_back(dims == 3 ? run.goals[goal + 2] : 0.0);
                sx.push_back(run.start[k * dims]), sy.push_back(run.start[k * dims + 1]);
                sz.push_back(dims == 3 ? run.start[k * dims + 2] : 0.0);
                const auto from = run.path_start[k], to = run.path_start[k + 1];
                std::vector<double> xy(run.path.begin() + std::ptrdiff_t(from * dims),
                                       run.path.begin() + std::ptrdiff_t(to * dims));
                paths.append(to_numpy(xy.data(), {pyb::ssize_t(to - from), dims}));
            }
            pyb::dict d;
            d["goal"] = to_numpy(run.start_goal.data(), {n});
            d["goal_x"] = to_numpy(gx.data(), {n});
            d["goal_y"] = to_numpy(gy.data(), {n});
            d["start_x"] = to_numpy(sx.data(), {n});
            d["start_y"] = to_numpy(sy.data(), {n});
            if (dims == 3) {
                d["goal_z"] = to_numpy(gz.data(), {n});
                d["start_z"] = to_numpy(sz.data(), {n});
            }
            d["success"] = to_numpy(run.success.data(), {n}).attr("astype")("bool");
            d["path_m"] = to_numpy(run.path_m.data(), {n});
            d["shortest_m"] = to_numpy(run.shortest_m.data(), {n});
            d["time_s"] = to_numpy(run.time_s.data(), {n});
            pyb::list failure;  // why each start failed: "" when it arrived (docs/navigation.md#why-a-start-fails)
            for (const int c : run.failure) failure.append(to_string(FailureClass(c)));
            d["failure"] = failure;
            d["paths"] = paths;
            d["learn_s"] = run.learn_s;
            d["coverage"] = run.coverage;
            d["visits"] = run.visits;
            d["goal_cells"] =
                std::vector<int>(run.goal_cells.begin(), run.goal_cells.begin() + std::ptrdiff_t(run.n_goals()));
            return d;
        },
        pyb::arg("world"), pyb::arg("goals"), pyb::arg("model") = "2d", pyb::arg("seed") = 0,
        ("One navigation run (docs/navigation.md): learning, then starts per goal. world: a bvc3d.World, or a preset "
         "name or world file as navigate's --world. goals: (N, 2) on the floor or (N, 3) for the flying agent "
         "(docs/navigation.md#flying-to-goals-in-3-d). dict of arrays, one entry per start (goal, goal_x, goal_y, "
         "start_x, start_y, and goal_z, start_z in 3-D, success, path_m, shortest_m, time_s, failure (why it failed, "
         "\"\" when it arrived), paths of (M, 2) or "
         "(M, 3)), and learn_s, coverage, visits, goal_cells. Keywords as a navigation YAML's keys: the sections "
         "navigation=, adjacency=, reward=, flight= as dicts; policy= (" +
         policy_names_text() +
         ") and the policy's own section as a dict (e.g. authors=dict(...)); or flat, the navigation, reward and "
         "adjacency parameters (below; flight's after them):\n" +
         describe(NavigationParams::table(), NavigationParams{}) + describe(RewardParams::table(), RewardParams{}) +
         "flight:\n" + describe(FlightParams::table(), FlightParams{}))
            .c_str());
}

}  // namespace bvc3d::py

// The authors' controller's pieces by hand (navigation/authors_choice.hpp, docs/navigation.md#the-authors-controller):
// the turning rollouts, the scale mix, the heading rule, the safety sectors and the reliability bookkeeping, with
// the random draws as arguments, so that a test can hold them against a transcription of SPEC §17.2.
#include "bindings.hpp"

#include <cmath>

#include "bvc3d/agent/authors_grid.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/navigation/authors_choice.hpp"
#include "bvc3d/navigation/sparse_adjacency.hpp"

namespace bvc3d::py {

namespace {

AuthorsParams authors_of(const pyb::kwargs& kwargs) {
    AuthorsParams p;
    apply_kwargs(p, AuthorsParams::table(), kwargs);
    return p;
}

std::vector<double> values_of(const pyb::handle& obj, const std::string& name) {
    const auto a = real_array(obj, name);
    return {a.data(), a.data() + a.size()};
}

// A hand-made adjacency (n_dir, n, n) as the frozen copy navigation reads (float32 weights, every one kept).
struct HandMade {
    std::shared_ptr<SparseAdjacency> copy;
    std::vector<double> column_sums;
    std::size_t n = 0;
};
HandMade hand_made(const pyb::handle& w_rec) {
    const auto w = real_array_f32(w_rec, "w_rec");
    if (w.ndim() != 3 || w.shape(1) != w.shape(2) || w.shape(0) < 1)
        throw InputError("w_rec must be an (n_dir, n, n) array");
    AdjacencyParams params;
    params.n_hd = static_cast<int>(w.shape(0));
    HdAdjacency adj(static_cast<int>(w.shape(1)), params);
    adj.set_weights({w.data(), std::size_t(w.size())});
    HandMade h;
    h.copy = std::make_shared<SparseAdjacency>(adj, 0.0);
    h.column_sums = h.copy->column_sums();
    h.n = std::size_t(w.shape(1));
    return h;
}

std::vector<double> rates_of(const pyb::handle& obj, const std::string& name, std::size_t n) {
    auto v = values_of(obj, name);
    if (v.size() != n) throw InputError(name + " must hold " + std::to_string(n) + " values");
    return v;
}

pyb::dict rollouts_dict(const TurningRollouts& r) {
    const auto D = pyb::ssize_t(r.R.size());
    std::vector<double> V;
    for (const Vec2& v : r.V) V.push_back(v.x()), V.push_back(v.y());
    pyb::dict d;
    d["R"] = to_numpy(r.R.data(), {D});
    d["V"] = to_numpy(V.data(), {D, 2});
    d["Var"] = to_numpy(r.Var.data(), {D});
    d["products"] = r.products;
    return d;
}

pyb::dict mix_dict(const ScaleMix& m) {
    const auto S = pyb::ssize_t(m.scales), D = pyb::ssize_t(m.dirs);
    pyb::dict d;
    d["P_ds"] = to_numpy(m.P_ds.data(), {S, D});
    d["P"] = to_numpy(m.P.data(), {S, D});
    for (const auto& [key, v] : {std::pair{"M", &m.M},
                                 {"H", &m.H},
                                 {"H_smoothed", &m.H_smoothed},
                                 {"iota", &m.iota},
                                 {"q", &m.q},
                                 {"P_s", &m.P_s}})
        d[key] = to_numpy(v->data(), {S});
    return d;
}

pyb::object choice_object(const std::optional<HeadingChoice>& h, std::size_t scales, std::size_t dirs) {
    if (!h) return pyb::none();
    pyb::dict d;
    d["heading"] = h->heading;
    d["c"] = to_numpy(h->c.data(), {2});
    d["rule"] = to_string(h->rule);
    d["P_prime"] = to_numpy(h->P_prime.data(), {pyb::ssize_t(scales), pyb::ssize_t(dirs)});
    d["scale_weights"] = to_numpy(h->scale_weights.data(), {pyb::ssize_t(scales)});
    return d;
}

std::vector<Vec2> pairs_of(const pyb::handle& obj, std::size_t count) {
    const auto v = values_of(obj, "V");
    if (v.size() != 2 * count) throw InputError("V must hold a 2-vector per (scale, direction)");
    std::vector<Vec2> out;
    for (std::size_t i = 0; i < count; ++i) out.emplace_back(v[2 * i], v[2 * i + 1]);
    return out;
}

}  // namespace

void bind_authors(pyb::module_& m) {
    const std::string params =
        "Keywords: the authors policy's parameters:\n" + describe(AuthorsParams::table(), AuthorsParams{});
    m.def(
        "authors_rollouts",
        [](const pyb::object& w_rec, const pyb::object& a0, const pyb::object& w_reward, const pyb::object& uniforms,
           const pyb::kwargs& kwargs) {
            const HandMade h = hand_made(w_rec);
            const auto r =
                turning_rollouts(*h.copy, h.column_sums, rates_of(w_reward, "w_reward", h.n), rates_of(a0, "a0", h.n),
                                 values_of(uniforms, "uniforms"), authors_of(kwargs));
            return rollouts_dict(r);
        },
        pyb::arg("w_rec"), pyb::arg("a0"), pyb::arg("w_reward"), pyb::arg("uniforms"),
        ("One scale's turning rollouts (SPEC §17.2) through a hand-made adjacency w_rec (n_dir, n, n; float32 "
         "weights), from rates a0, with the turns' uniforms ((steps − 1) × n_dir × samples, in that order): dict R, "
         "V (n_dir, 2), Var, products (distinct states computed). " +
         params)
            .c_str());
    m.def(
        "authors_mix",
        [](const pyb::object& R, const pyb::object& Var, const pyb::object& reliability, const pyb::object& H_prev,
           const pyb::kwargs& kwargs) {
            const auto r = real_array(R, "R");
            if (r.ndim() != 2) throw InputError("R must be scales × directions");
            const auto prev = H_prev.is_none() ? std::vector<double>{} : values_of(H_prev, "H_prev");
            return mix_dict(mix_scales(values_of(R, "R"), values_of(Var, "Var"), std::size_t(r.shape(1)),
                                       values_of(reliability, "reliability"), prev, authors_of(kwargs)));
        },
        pyb::arg("R"), pyb::arg("Var"), pyb::arg("reliability"), pyb::arg("H_prev") = pyb::none(),
        ("The authors' scale mix (SPEC §17.2): R, Var scales × directions, ρ per scale, H̃ of the decision before "
         "(None: a start's first). dict P_ds, M, H, H_smoothed, iota, q, P_s, P. " +
         params)
            .c_str());
    m.def(
        "authors_heading",
        [](const pyb::object& P, const pyb::object& R, const pyb::object& V, const pyb::object& safe) {
            const auto p = values_of(P, "P");
            const auto open = values_of(safe, "safe");
            const std::vector<char> flags(open.begin(), open.end());
            const auto h = heading_rule(p, values_of(R, "R"), pairs_of(V, p.size()), flags);
            return choice_object(h, flags.empty() ? 0 : p.size() / flags.size(), flags.size());
        },
        pyb::arg("P"), pyb::arg("R"), pyb::arg("V"), pyb::arg("safe"),
        "The authors' heading rule: P, R scales × directions, V scales × directions × 2, safe per direction. None when "
        "no direction is safe, else dict heading (rad, [0, 2π)), c, rule (mix, opposed, fallback), P_prime, "
        "scale_weights.");
    m.def(
        "sector_minima",
        [](const pyb::object& ranges, const pyb::object& azimuths, int n_dir, const std::string& sector) {
            if (sector != "authors" && sector != "centred")
                throw InputError("sector must be authors or centred, not '" + sector + "'");
            const auto out = sector_minima(values_of(ranges, "ranges"), values_of(azimuths, "azimuths"), n_dir,
                                           sector == "authors" ? SafetySector::authors : SafetySector::centred);
            return to_numpy(out.data(), {pyb::ssize_t(out.size())});
        },
        pyb::arg("ranges"), pyb::arg("azimuths"), pyb::arg("n_dir") = 8, pyb::arg("sector") = "authors",
        "The least range in each direction's sector: authors [θ_d, θ_d + 2π/n), centred [θ_d − π/n, θ_d + π/n).");
    m.def(
        "authors_decide",
        [](const pyb::list& scales, const pyb::object& uniforms, const pyb::object& sector_min,
           const pyb::object& reliability, const pyb::object& H_prev, const pyb::kwargs& kwargs) {
            std::vector<HandMade> made;
            std::vector<std::vector<double>> rates, weights;
            for (const auto& item : scales) {
                const auto t = item.cast<pyb::tuple>();
                if (t.size() != 3) throw InputError("each scale is (w_rec, a, w_reward)");
                made.push_back(hand_made(t[0]));
                rates.push_back(rates_of(t[1], "a", made.back().n));
                weights.push_back(rates_of(t[2], "w_reward", made.back().n));
            }
            std::vector<DecisionScale> in;
            for (std::size_t s = 0; s < made.size(); ++s)
                in.push_back({made[s].copy.get(), made[s].column_sums, weights[s], rates[s]});
            const auto prev = H_prev.is_none() ? std::vector<double>{} : values_of(H_prev, "H_prev");
            const auto d = authors_decide(in, values_of(uniforms, "uniforms"), values_of(sector_min, "sector_min"),
                                          values_of(reliability, "reliability"), prev, authors_of(kwargs));
            pyb::dict out;
            pyb::list rollouts;
            for (const auto& r : d.rollouts) rollouts.append(rollouts_dict(r));
            out["rollouts"] = rollouts;
            out["mix"] = mix_dict(d.mix);
            out["choice"] = choice_object(d.choice, d.mix.scales, d.mix.dirs);
            out["H_smoothed"] = to_numpy(d.mix.H_smoothed.data(), {pyb::ssize_t(d.mix.scales)});
            return out;
        },
        pyb::arg("scales"), pyb::arg("uniforms"), pyb::arg("sector_min"), pyb::arg("reliability"),
        pyb::arg("H_prev") = pyb::none(),
        ("One decision of the authors' controller, as the policy takes it: scales a list of (w_rec, a, w_reward), the "
         "flat uniforms (scale → step → direction → sample), the least range per direction, ρ per scale, H̃ before. "
         "dict rollouts, mix, choice (None: an exploration block), H_smoothed. " +
         params)
            .c_str());

    m.def(
        "authors_grid",
        [](const pyb::object& world, double cell, double inflate) {
            const auto w = world_of(world, "authors_grid: world");
            const RobotParams robot;
            const BodyCollider body(w->description(), robot.radius, robot.height);
            const AuthorsGrid grid(body, cell, inflate);
            std::vector<std::uint8_t> blocked(grid.blocked().begin(), grid.blocked().end());
            pyb::dict d;
            d["blocked"] = to_numpy(blocked.data(), {grid.rows(), grid.cols()}).attr("astype")("bool");
            d["west"] = grid.west();
            d["north"] = grid.north();
            d["cell"] = grid.cell();
            return d;
        },
        pyb::arg("world"), pyb::arg("cell") = 0.1, pyb::arg("inflate") = 0.5,
        "The authors' planner's grid of a world (SPEC §17.3, docs/navigation.md#the-authors-protocol): dict blocked "
        "(rows × columns, row 0 the north edge), west, north, cell.");
    m.def(
        "authors_path",
        [](const pyb::object& world, const pyb::object& start, const pyb::object& goal, double radius, double cell,
           double inflate) {
            const auto w = world_of(world, "authors_path: world");
            const RobotParams robot;
            const BodyCollider body(w->description(), robot.radius, robot.height);
            const AuthorsGrid grid(body, cell, inflate);
            const auto s = values_of(start, "start"), g = values_of(goal, "goal");
            if (s.size() != 2 || g.size() != 2) throw InputError("start and goal are (x, y)");
            const auto path = grid.shortest({s[0], s[1]}, {g[0], g[1]}, radius);
            pyb::dict d;
            d["found"] = bool(path);
            d["length"] = path ? path->length : 0.0;
            std::vector<int> cells;
            if (path)
                for (const auto& [c, r] : path->cells) cells.push_back(c), cells.push_back(r);
            d["cells"] = to_numpy(cells.data(), {pyb::ssize_t(cells.size() / 2), 2});
            return d;
        },
        pyb::arg("world"), pyb::arg("start"), pyb::arg("goal"), pyb::arg("radius") = 1.0, pyb::arg("cell") = 0.1,
        pyb::arg("inflate") = 0.5,
        "The authors' optimal path (SPEC §17.3) from start's cell to the goal's disc of `radius`: dict found, length "
        "(m), cells (N × 2 of column, row).");

    pyb::class_<AuthorsReliability>(m, "AuthorsReliability",
                                    "The authors' per-start reliability, loop and exploration bookkeeping (SPEC "
                                    "§17.2): begin(heading_deg) → 'explore' or 'decide'; after a decision's block, "
                                    "movement_headings(list of degrees) then end(scale_weights, contact).")
        .def(pyb::init([](std::size_t scales, const pyb::kwargs& kwargs) {
                 return AuthorsReliability(scales, authors_of(kwargs));
             }),
             pyb::arg("scales"))
        .def("begin",
             [](AuthorsReliability& r, double heading_deg) {
                 return r.begin(heading_deg) == AuthorsReliability::Phase::explore ? "explore" : "decide";
             })
        .def("movement_headings",
             [](AuthorsReliability& r, const pyb::object& h) { r.movement_headings(values_of(h, "headings")); })
        .def("end", [](AuthorsReliability& r, const pyb::object& w,
                       bool contact) { r.end(values_of(w, "scale_weights"), contact); })
        .def_property_readonly("rho", [](const AuthorsReliability& r) { return r.rho(); })
        .def_property_readonly("cooldown", [](const AuthorsReliability& r) { return r.cooldown(); })
        .def_property_readonly("contributions", [](const AuthorsReliability& r) { return r.contributions(); })
        .def_property_readonly("accumulated", &AuthorsReliability::accumulated)
        .def_property_readonly("loops", &AuthorsReliability::loops)
        .def_property_readonly("since_loop", &AuthorsReliability::since_loop)
        .def_property_readonly("force_explore", &AuthorsReliability::force_explore);
}

}  // namespace bvc3d::py

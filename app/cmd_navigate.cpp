// bvc3d navigate: navigation to goals (docs/navigation.md): learning runs, then starts per goal, written as
// starts.csv, learning.csv, paths.csv, reward_map.csv, summary.csv/.md and figures. Each finished learning run is
// kept in runs/seed-N.nav (exact numbers and a fingerprint of everything that fixes it): a run interrupted (Ctrl-C,
// a kill) and started again with the same options takes the finished seeds from there and writes the same files.
#include <algorithm>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/config/yaml_reader.hpp"
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/experiment/navigation.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "option_groups.hpp"
#include "python_module.hpp"
#include "run_options.hpp"
#include "table_options.hpp"

namespace bvc3d::cli {

namespace {

struct NavigateOptions {
    std::string config, goals, model = "2d";
    WorldOptions world;
    int seeds = 1;
    std::uint64_t first_seed = 0;
    TableOptions<NavigationParams> nav{NavigationParams::table()};
    bool dry_run = false;
    RunOptions run;  // --out, --jobs, --no-figures
};

// What one command runs: models × seeds in a world with its goals, and every parameter.
struct NavigatePlan {
    std::string world, lean = "+x+y";
    std::optional<double> tilt;
    config::MissingModels missing_models = config::MissingModels::error;
    std::vector<NavigationGoal> goals;
    std::vector<std::string> models;  // as given: a preset name or a model file
    int seeds = 1;
    std::uint64_t first_seed = 0;
    NavigationParams nav;
    AdjacencyParams adjacency;
    RewardParams reward;
    FlightParams flight;
};

// A goal of 2 numbers (on the floor) or 3 (in the air, the flying agent); else nothing.
std::optional<NavigationGoal> goal_of(const std::vector<double>& v) {
    if (v.size() == 2) return NavigationGoal(v[0], v[1]);
    if (v.size() == 3) return NavigationGoal(v[0], v[1], v[2]);
    return std::nullopt;
}

// "x,y;x,y" or "x,y,z;x,y,z": the goals (InputError naming the bad one).
std::vector<NavigationGoal> parse_goals(const std::string& text) {
    std::vector<NavigationGoal> out;
    std::stringstream all(text);
    std::string item;
    while (std::getline(all, item, ';')) {
        if (item.find_first_not_of(" \t") == std::string::npos) continue;
        std::vector<double> v;
        std::stringstream numbers(item);
        for (std::string n; std::getline(numbers, n, ',');) v.push_back(parse_number(n, "--goals"));
        const auto goal = goal_of(v);
        if (!goal || item.back() == ',')
            throw InputError("--goals: '" + item + "' is not x,y or x,y,z (give goals as x,y;x,y or x,y,z;x,y,z)");
        out.push_back(*goal);
    }
    return out;
}

NavigatePlan plan_of_options(const NavigateOptions& o) {
    if (o.world.world.empty()) throw InputError("navigate: give --world and --goals, or --config");
    if (o.seeds < 1) throw InputError("--seeds: must be at least 1");
    NavigatePlan p;
    const WorldSpec world = o.world.spec();
    p.world = world.source, p.tilt = world.tilt_deg, p.lean = world.lean, p.missing_models = world.missing_models;
    p.goals = parse_goals(o.goals);
    p.models = model_list(o.model);
    p.seeds = o.seeds, p.first_seed = o.first_seed;
    o.nav.apply(p.nav);
    p.nav.validate();
    return p;
}

// The sweep-friendly YAML (docs/navigation.md#a-yaml-file): world (a preset or a file, relative to the YAML's
// folder), tilt, lean, goals ([[x, y], ...]), models (a name or a list), seeds, first_seed, and the parameter
// tables navigation:, adjacency:, reward:. Any other key: InputError naming it.
NavigatePlan plan_of_yaml(const std::string& file) {
    const auto v = config::YamlView::load_file(file);
    v.expect_map({"world", "tilt", "lean", "missing_models", "goals", "models", "seeds", "first_seed", "navigation",
                  "adjacency", "reward", "flight"});
    NavigatePlan p;
    p.world = config::path_in_file(v, v["world"].as_string());
    if (v.has("tilt")) p.tilt = v["tilt"].as_double();
    p.lean = v.get("lean", p.lean);
    if (v.has("missing_models")) try {
            p.missing_models = config::parse_missing_models(v["missing_models"].as_string());
        } catch (const ConfigError&) {
            throw;
        } catch (const InputError& e) {
            v["missing_models"].fail(e.what());
        }
    const auto goals = v["goals"];
    if (!goals.is_sequence()) goals.fail("must be a list of [x, y] or of [x, y, z]");
    for (std::size_t i = 0; i < goals.size(); ++i) {
        const auto goal = goal_of(goals.at(i).as_doubles());
        if (!goal) goals.at(i).fail("must be [x, y] (on the floor) or [x, y, z] (flying)");
        p.goals.push_back(*goal);
    }
    if (v.has("models")) {
        const auto m = v["models"];
        if (m.is_scalar()) {
            p.models.push_back(m.as_string());
        } else {
            if (m.size() == 0) m.fail("must name at least one model");
            for (std::size_t i = 0; i < m.size(); ++i) p.models.push_back(m.at(i).as_string());
        }
    } else {
        p.models = {"2d"};
    }
    for (std::string& m : p.models) m = config::path_in_file(v, m);
    p.seeds = v.get("seeds", 1);
    if (p.seeds < 1) v["seeds"].fail("must be at least 1");
    if (v.has("first_seed")) p.first_seed = v["first_seed"].as_uint64();
    if (v.has("navigation")) config::read_table(v["navigation"], p.nav, NavigationParams::table());
    if (v.has("adjacency")) config::read_table(v["adjacency"], p.adjacency, AdjacencyParams::table());
    if (v.has("reward")) config::read_table(v["reward"], p.reward, RewardParams::table());
    if (v.has("flight")) config::read_table(v["flight"], p.flight, FlightParams::table());
    return p;
}

// A world or model file by its stem (configs/worlds/nav-open.yaml: nav-open), a preset by its name.
std::string label_of(const std::string& name_or_file) {
    const std::filesystem::path path(name_or_file);
    return std::filesystem::is_regular_file(path) ? path.stem().string() : name_or_file;
}

double quantile(std::vector<double> v, double q) {
    if (v.empty()) return std::nan("");
    std::sort(v.begin(), v.end());
    const double at = q * double(v.size() - 1);
    const auto lo = static_cast<std::size_t>(at);
    const auto hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (at - double(lo)) * (v[hi] - v[lo]);
}

// A learning run's results as the command writes them, exactly (shortest round-trip numbers): runs/seed-N.nav.
constexpr const char* run_magic = "bvc3d-navigation-run 1";

std::string number_text(double v) {
    char buf[32];
    return {buf, std::to_chars(buf, buf + sizeof buf, v).ptr};
}

// Points as x y (on the floor) or x y z (a flying run: `dims` 3).
void save_run(const std::filesystem::path& file, const std::string& fingerprint, const NavigationRun& r, int dims) {
    const auto point = [&](std::ostream& o, const Vec3& p) {
        o << number_text(p.x()) << ' ' << number_text(p.y());
        if (dims == 3) o << ' ' << number_text(p.z());
    };
    AtomicFile f(file);
    auto& o = f.stream();
    o << run_magic << '\n' << fingerprint << "\nend-fingerprint\n";
    o << number_text(r.learn_s) << ' ' << number_text(r.coverage) << ' ' << r.visits.size() << '\n';
    for (std::size_t g = 0; g < r.visits.size(); ++g) {
        o << r.visits[g] << ' ' << r.goal_cells[g] << ' ' << r.reward_maps[g].size() << '\n';
        for (const auto& m : r.reward_maps[g])
            o << number_text(m.p.x()) << ' ' << number_text(m.p.y()) << ' ' << number_text(m.reward) << '\n';
    }
    o << r.starts.size() << '\n';
    for (const auto& st : r.starts) {
        o << st.goal << ' ';
        point(o, st.start);
        o << ' ' << st.success << ' ' << number_text(st.path_m) << ' ' << number_text(st.shortest_m) << ' '
          << number_text(st.time_s) << ' ' << st.path.size() << '\n';
        for (const Vec3& p : st.path) point(o, p), o << '\n';
    }
    o << "end\n";
    f.commit();
}

// The run kept in `file` if it is whole and was made with `fingerprint`; else nothing.
std::optional<NavigationRun> load_run(const std::filesystem::path& file, const std::string& fingerprint, int dims) {
    std::ifstream in(file);
    std::string line, fp;
    if (!std::getline(in, line) || line != run_magic) return std::nullopt;
    while (std::getline(in, line) && line != "end-fingerprint") fp += (fp.empty() ? "" : "\n") + line;
    if (fp != fingerprint) return std::nullopt;
    std::string word;
    bool ok = true;
    auto real = [&] {
        double v = 0;
        ok = ok && (in >> word) && std::from_chars(word.data(), word.data() + word.size(), v).ec == std::errc{};
        return v;
    };
    auto count = [&] {
        long long v = 0;
        ok = ok && (in >> v) && v >= 0;
        return static_cast<std::size_t>(std::max(v, 0LL));
    };
    auto point = [&] {
        Vec3 p = Vec3::Zero();
        for (int d = 0; d < dims; ++d) p[d] = real();
        return p;
    };
    NavigationRun r;
    r.learn_s = real();
    r.coverage = real();
    const std::size_t goals = count();
    for (std::size_t g = 0; ok && g < goals; ++g) {
        int visits = 0, cell = 0;
        ok = ok && (in >> visits >> cell);
        r.visits.push_back(visits), r.goal_cells.push_back(cell);
        r.reward_maps.emplace_back();
        for (std::size_t m = count(); ok && m > 0; --m) {
            const double x = real(), y = real();
            r.reward_maps.back().push_back({Vec2(x, y), real()});
        }
    }
    for (std::size_t n = count(); ok && n > 0; --n) {
        NavigationStart st;
        ok = ok && (in >> st.goal);
        st.start = point();
        ok = ok && (in >> st.success);
        st.path_m = real(), st.shortest_m = real(), st.time_s = real();
        for (std::size_t m = count(); ok && m > 0; --m) st.path.push_back(point());
        r.starts.push_back(std::move(st));
    }
    if (!ok || !(in >> word) || word != "end") return std::nullopt;
    return r;
}

// Everything that fixes a learning run's results.
std::string run_fingerprint(const NavigatePlan& o, const NavigationSetup& s, std::uint64_t seed) {
    std::string fp = "world: " + WorldSpec{o.world, o.tilt, o.lean, o.missing_models}.fingerprint() + "\nmodel:\n" +
                     config::model_to_yaml(s.model) + "goals:";
    for (const NavigationGoal& g : s.goals)
        fp += " " + number_text(g.x()) + "," + number_text(g.y()) + (g.dims == 3 ? "," + number_text(g.z()) : "");
    if (s.dims() == 3) fp += "\nflight:\n" + params::yaml_lines(FlightParams::table(), s.flight, "  ");
    fp += "\nnavigation:\n" + params::yaml_lines(NavigationParams::table(), s.nav, "  ") + "adjacency:\n" +
          params::yaml_lines(AdjacencyParams::table(), s.adjacency, "  ") + "reward:\n" +
          params::yaml_lines(RewardParams::table(), s.reward, "  ") + "seed: " + std::to_string(seed);
    return fp;
}

void navigate_command(const NavigateOptions& o) {
    o.run.check();
    const NavigatePlan plan = o.config.empty() ? plan_of_options(o) : plan_of_yaml(o.config);
    NavigationSetup setup;
    setup.nav = plan.nav, setup.adjacency = plan.adjacency, setup.reward = plan.reward, setup.flight = plan.flight;
    setup.goals = plan.goals;
    std::vector<ModelSpec> models;
    std::optional<World> world;
    try {  // before anything is written; a YAML file's errors name it
        for (const auto& m : plan.models) {
            models.push_back(config::resolve_model(m));
            check_scales(models.back(), setup.reward);
        }
        world.emplace(config::resolve_world(plan.world, plan.tilt, plan.lean, plan.missing_models));
        warn_left_out(world->description());
        check_goals(*world, setup);
        for (const ModelSpec& m : models) check_model(m, setup);
    } catch (const InputError& e) {
        if (o.config.empty()) throw;
        throw InputError(o.config + ": " + e.what());
    }
    const std::string world_name = label_of(plan.world) + (plan.tilt ? "-" + format_number(*plan.tilt) : "");
    if (o.dry_run) {
        std::printf("%s: %zu goal(s), %zu model(s) × %d seed(s) = %zu learning runs, %d starts per goal each\n",
                    world_name.c_str(), plan.goals.size(), models.size(), plan.seeds,
                    models.size() * std::size_t(plan.seeds), plan.nav.starts);
        return;
    }
    const std::filesystem::path out = o.run.out;
    if (out.empty()) throw InputError("--out: give an output folder");
    const auto lock = lock_output_folder(out);

    // The learning runs first (each kept as soon as it is done), then the files, all at once.
    const std::filesystem::path runs = out / "runs";
    ensure_writable_directory(runs);
    struct Done {
        std::size_t model;
        std::uint64_t seed;
        NavigationRun run;
    };
    std::vector<Done> results;
    for (std::size_t m = 0; m < models.size(); ++m)
        for (int k = 0; k < plan.seeds; ++k) results.push_back({m, plan.first_seed + std::uint64_t(k), {}});
    // Each learning run depends on its model and seed alone: --jobs of them at once write the same files as one.
    run_in_parallel(results.size(), o.run.jobs, [&](std::size_t t) {
        Done& d = results[t];
        const std::string prefix = models.size() > 1 ? label_of(plan.models[d.model]) : "";
        const std::string name = (prefix.empty() ? "" : prefix + " ") + "seed " + std::to_string(d.seed);
        const auto kept = runs / ((prefix.empty() ? "" : prefix + "-") + "seed-" + std::to_string(d.seed) + ".nav");
        NavigationSetup mine = setup;
        mine.model = models[d.model];
        const std::string fingerprint = run_fingerprint(plan, mine, d.seed);
        if (std::optional<NavigationRun> kept_run = load_run(kept, fingerprint, mine.dims())) {
            std::fprintf(stderr, "%s: already done (%s)\n", name.c_str(), kept.string().c_str());
            d.run = std::move(*kept_run);
            return;
        }
        std::fprintf(stderr, "%s: learning...\n", name.c_str());
        d.run = navigate(*world, mine, d.seed);
        save_run(kept, fingerprint, d.run, mine.dims());
        std::fprintf(stderr, "%s: learned in %.2f h (coverage %.3f); %zu starts\n", name.c_str(), d.run.learn_s / 3600,
                     d.run.coverage, d.run.starts.size());
    });

    AtomicFile starts(out / "starts.csv"), paths(out / "paths.csv"), maps(out / "reward_map.csv"),
        learning(out / "learning.csv");
    // A flying run (goals x,y,z) appends goal_z,start_z to starts.csv and z to paths.csv and summary.csv (goal_z).
    const bool flying = setup.dims() == 3;
    starts.stream() << "world,model,seed,goal_x,goal_y,start_x,start_y,success,path_m,shortest_m,path_ratio,time_s"
                    << (flying ? ",goal_z,start_z\n" : "\n");
    paths.stream() << "model,seed,start,x,y" << (flying ? ",z\n" : "\n");
    maps.stream() << "model,seed,goal,x,y,reward\n";
    learning.stream() << "model,seed,learn_s,coverage,goal,visits,goal_cell\n";
    // Per model and goal: the path ratios of the successes, successes, starts, learning times.
    const std::size_t n_goals = setup.goals.size(), n_cells = models.size() * n_goals;
    std::vector<std::vector<double>> ratios(n_cells), learn_s(n_cells);
    std::vector<int> reached(n_cells, 0), tried(n_cells, 0);
    for (const Done& d : results) {
        const NavigationRun& r = d.run;
        const std::string& model = plan.models[d.model];
        for (std::size_t g = 0; g < n_goals; ++g) {
            learning.stream() << model << ',' << d.seed << ',' << r.learn_s << ',' << r.coverage << ',' << g << ','
                              << r.visits[g] << ',' << r.goal_cells[g] << '\n';
            learn_s[d.model * n_goals + g].push_back(r.learn_s);
            for (const auto& m : r.reward_maps[g])
                maps.stream() << model << ',' << d.seed << ',' << g << ',' << m.p.x() << ',' << m.p.y() << ','
                              << m.reward << '\n';
        }
        for (std::size_t i = 0; i < r.starts.size(); ++i) {
            const auto& s = r.starts[i];
            const NavigationGoal& goal = setup.goals[std::size_t(s.goal)];
            const double ratio = s.path_m / s.shortest_m;
            starts.stream() << world_name << ',' << model << ',' << d.seed << ',' << goal.x() << ',' << goal.y() << ','
                            << s.start.x() << ',' << s.start.y() << ',' << (s.success ? 1 : 0) << ',' << s.path_m << ','
                            << s.shortest_m << ',' << ratio << ',' << s.time_s;
            if (flying) starts.stream() << ',' << goal.z() << ',' << s.start.z();
            starts.stream() << '\n';
            for (const Vec3& p : s.path) {
                paths.stream() << model << ',' << d.seed << ',' << i << ',' << p.x() << ',' << p.y();
                if (flying) paths.stream() << ',' << p.z();
                paths.stream() << '\n';
            }
            const std::size_t c = d.model * n_goals + std::size_t(s.goal);
            ++tried[c];
            if (s.success) ++reached[c], ratios[c].push_back(ratio);
        }
    }
    AtomicFile csv(out / "summary.csv"), md(out / "summary.md");
    csv.stream() << "world,model,goal_x,goal_y,seeds,starts,success_rate,path_ratio_median,path_ratio_q25,"
                    "path_ratio_q75,learn_h_mean"
                 << (flying ? ",goal_z\n" : "\n");
    md.stream()
        << "# Navigation: " << world_name << ", " << plan.seeds << " learning run(s) per model\n\n"
        << "| model | goal | starts | success | path ratio median [q25, q75] (successes) | learning h (mean) |\n"
        << "|---|---|---|---|---|---|\n";
    for (std::size_t c = 0; c < n_cells; ++c) {
        const std::string& model = plan.models[c / n_goals];
        const NavigationGoal& goal = setup.goals[c % n_goals];
        double mean_learn = 0;
        for (double t : learn_s[c]) mean_learn += t / 3600 / double(learn_s[c].size());
        const double rate = tried[c] ? double(reached[c]) / tried[c] : 0.0;
        const double med = quantile(ratios[c], 0.5), q25 = quantile(ratios[c], 0.25), q75 = quantile(ratios[c], 0.75);
        csv.stream() << world_name << ',' << model << ',' << goal.x() << ',' << goal.y() << ',' << plan.seeds << ','
                     << tried[c] << ',' << rate << ',' << med << ',' << q25 << ',' << q75 << ',' << mean_learn;
        if (flying) csv.stream() << ',' << goal.z();
        csv.stream() << '\n';
        char where[96], line[256];
        if (flying) std::snprintf(where, sizeof where, "(%g, %g, %g)", goal.x(), goal.y(), goal.z());
        else std::snprintf(where, sizeof where, "(%g, %g)", goal.x(), goal.y());
        std::snprintf(line, sizeof line, "| %s | %d | %.0f %% | %.2f [%.2f, %.2f] | %.2f |\n", where, tried[c],
                      100 * rate, med, q25, q75, mean_learn);
        md.stream() << "| " << model << " " << line;
    }
    for (AtomicFile* f : {&starts, &paths, &maps, &learning, &csv, &md}) f->commit();
    std::printf("wrote %s (starts.csv, summary.csv, summary.md)\n", out.string().c_str());
    if (!o.run.no_figures) {
        const ModuleRun fig = run_python_module("bvc3d.navigation_figures", {out.string(), world_name}, true);
        if (fig.status != 0) std::fprintf(stderr, "bvc3d: warning: no figures (%s)\n", fig.last_error_line().c_str());
    }
}

}  // namespace

void add_navigate_command(CLI::App& app) {
    auto o = std::make_shared<NavigateOptions>();
    auto* cmd = app.add_subcommand("navigate",
                                   "Navigation to goals: learn by a random walk, then reach each goal "
                                   "from random starts (docs/navigation.md)");
    auto* config = cmd->add_option("--config", o->config,
                                   "A YAML file: world, goals, models, seeds and parameters (docs/navigation.md)");
    std::vector<CLI::Option*> given = o->world.add_to(*cmd, "", "");
    given.push_back(cmd->add_option("--goals", o->goals,
                                    "Goals on the floor, x,y[;x,y...], or in the air for the flying agent, "
                                    "x,y,z[;x,y,z...] (m)"));
    given.push_back(add_model_option(*cmd, o->model, ModelCount::list));
    given.push_back(cmd->add_option("--seeds", o->seeds, "Learning runs (seeds first-seed, first-seed+1, ...)")
                        ->capture_default_str());
    given.push_back(
        cmd->add_option("--first-seed", o->first_seed, "The first seed")->check(seed_check)->capture_default_str());
    static const NavigationParams defaults;
    for (CLI::Option* g : o->nav.add_to(*cmd, {"starts", "max_learn_hours", "coverage", "goal_visits"}, &defaults))
        given.push_back(g);
    for (CLI::Option* g : given) config->excludes(g);
    cmd->add_flag("--dry-run", o->dry_run, "Read and check everything, say what would run, and exit");
    o->run.add_out(*cmd, "Output folder (runs/ in it keeps each finished learning run, to resume)",
                   OutputKind::results_folder, {"runs"});
    o->run.add_jobs(*cmd, "Learning runs", " (the files are the same)");
    o->run.add_no_figures(*cmd);
    cmd->callback([o] { navigate_command(*o); });
}

}  // namespace bvc3d::cli

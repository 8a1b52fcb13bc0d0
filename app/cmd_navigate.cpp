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
#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/experiment/navigation.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "python_module.hpp"
#include "run_options.hpp"

namespace bvc3d::cli {

namespace {

struct NavigateOptions {
    std::string world, lean = "+x+y", goals, model = "2d";
    std::optional<double> tilt;
    int seeds = 1;
    std::uint64_t first_seed = 0;
    NavigationParams nav;
    RunOptions run;  // --out, --no-report
};

// "x,y;x,y": the goals (InputError naming the bad one).
std::vector<Vec2> parse_goals(const std::string& text) {
    std::vector<Vec2> out;
    std::stringstream all(text);
    std::string item;
    while (std::getline(all, item, ';')) {
        if (item.find_first_not_of(" \t") == std::string::npos) continue;
        const auto comma = item.find(',');
        if (comma == std::string::npos || item.find(',', comma + 1) != std::string::npos)
            throw InputError("--goals: '" + item + "' is not x,y (give goals as x,y;x,y)");
        out.emplace_back(parse_number(item.substr(0, comma), "--goals"),
                         parse_number(item.substr(comma + 1), "--goals"));
    }
    return out;
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

void save_run(const std::filesystem::path& file, const std::string& fingerprint, const NavigationRun& r) {
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
        o << st.goal << ' ' << number_text(st.start.x()) << ' ' << number_text(st.start.y()) << ' ' << st.success << ' '
          << number_text(st.path_m) << ' ' << number_text(st.shortest_m) << ' ' << number_text(st.time_s) << ' '
          << st.path.size() << '\n';
        for (const Vec2& p : st.path) o << number_text(p.x()) << ' ' << number_text(p.y()) << '\n';
    }
    o << "end\n";
    f.commit();
}

// The run kept in `file` if it is whole and was made with `fingerprint`; else nothing.
std::optional<NavigationRun> load_run(const std::filesystem::path& file, const std::string& fingerprint) {
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
        const double x = real(), y = real();
        st.start = Vec2(x, y);
        ok = ok && (in >> st.success);
        st.path_m = real(), st.shortest_m = real(), st.time_s = real();
        for (std::size_t m = count(); ok && m > 0; --m) {
            const double px = real();
            st.path.emplace_back(px, real());
        }
        r.starts.push_back(std::move(st));
    }
    if (!ok || !(in >> word) || word != "end") return std::nullopt;
    return r;
}

// Everything that fixes a learning run's results.
std::string run_fingerprint(const NavigateOptions& o, const NavigationSetup& s, std::uint64_t seed) {
    std::string fp = "world: " + WorldSpec{o.world, o.tilt, o.lean}.fingerprint() + "\nmodel:\n" +
                     config::model_to_yaml(s.model) + "goals:";
    for (const Vec2& g : s.goals) fp += " " + number_text(g.x()) + "," + number_text(g.y());
    fp += "\nnavigation:\n" + params::yaml_lines(NavigationParams::table(), s.nav, "  ") + "adjacency:\n" +
          params::yaml_lines(AdjacencyParams::table(), s.adjacency, "  ") + "reward:\n" +
          params::yaml_lines(RewardParams::table(), s.reward, "  ") + "seed: " + std::to_string(seed);
    return fp;
}

void navigate_command(const NavigateOptions& o) {
    o.run.check();
    if (o.seeds < 1) throw InputError("--seeds: must be at least 1");
    NavigationSetup setup;
    setup.nav = o.nav;
    setup.nav.validate();
    setup.model = config::resolve_model(o.model);
    setup.goals = parse_goals(o.goals);
    const World world(config::resolve_world(o.world, o.tilt, o.lean));
    check_goals(world, setup);  // before anything is written
    const std::filesystem::path out = o.run.out;
    const auto lock = lock_output_folder(out);
    // A world file by its stem (configs/worlds/nav-open.yaml: nav-open), a preset by its name (and tilt).
    const std::filesystem::path wpath(o.world);
    const std::string world_name = (std::filesystem::is_regular_file(wpath) ? wpath.stem().string() : o.world) +
                                   (o.tilt ? "-" + format_number(*o.tilt) : "");

    // Per goal: the path ratios of the successes, successes, starts, learning times.
    const std::size_t n_goals = setup.goals.size();
    std::vector<std::vector<double>> ratios(n_goals), learn_s(n_goals);
    std::vector<int> reached(n_goals, 0), tried(n_goals, 0);
    // The learning runs first (each kept as soon as it is done), then the files, all at once.
    const std::filesystem::path runs = out / "runs";
    ensure_writable_directory(runs);
    std::vector<NavigationRun> results;
    for (int k = 0; k < o.seeds; ++k) {
        const std::uint64_t seed = o.first_seed + std::uint64_t(k);
        const auto seed_text = std::to_string(seed);
        const auto kept = runs / ("seed-" + seed_text + ".nav");
        const std::string fingerprint = run_fingerprint(o, setup, seed);
        std::optional<NavigationRun> done = load_run(kept, fingerprint);
        if (done) {
            std::fprintf(stderr, "seed %s: already done (%s)\n", seed_text.c_str(), kept.string().c_str());
        } else {
            std::fprintf(stderr, "seed %s: learning...\n", seed_text.c_str());
            done = navigate(world, setup, seed);
            save_run(kept, fingerprint, *done);
            std::fprintf(stderr, "seed %s: learned in %.2f h (coverage %.3f); %zu starts\n", seed_text.c_str(),
                         done->learn_s / 3600, done->coverage, done->starts.size());
        }
        results.push_back(std::move(*done));
    }
    AtomicFile starts(out / "starts.csv"), paths(out / "paths.csv"), maps(out / "reward_map.csv"),
        learning(out / "learning.csv");
    starts.stream() << "world,model,seed,goal_x,goal_y,start_x,start_y,success,path_m,shortest_m,path_ratio,time_s\n";
    paths.stream() << "seed,start,x,y\n";
    maps.stream() << "seed,goal,x,y,reward\n";
    learning.stream() << "seed,learn_s,coverage,goal,visits,goal_cell\n";
    for (int k = 0; k < o.seeds; ++k) {
        const std::uint64_t seed = o.first_seed + std::uint64_t(k);
        const NavigationRun& r = results[std::size_t(k)];
        for (std::size_t g = 0; g < n_goals; ++g) {
            learning.stream() << seed << ',' << r.learn_s << ',' << r.coverage << ',' << g << ',' << r.visits[g] << ','
                              << r.goal_cells[g] << '\n';
            learn_s[g].push_back(r.learn_s);
            for (const auto& m : r.reward_maps[g])
                maps.stream() << seed << ',' << g << ',' << m.p.x() << ',' << m.p.y() << ',' << m.reward << '\n';
        }
        for (std::size_t i = 0; i < r.starts.size(); ++i) {
            const auto& s = r.starts[i];
            const Vec2 goal = setup.goals[std::size_t(s.goal)];
            const double ratio = s.path_m / s.shortest_m;
            starts.stream() << world_name << ',' << o.model << ',' << seed << ',' << goal.x() << ',' << goal.y() << ','
                            << s.start.x() << ',' << s.start.y() << ',' << (s.success ? 1 : 0) << ',' << s.path_m << ','
                            << s.shortest_m << ',' << ratio << ',' << s.time_s << '\n';
            for (const Vec2& p : s.path) paths.stream() << seed << ',' << i << ',' << p.x() << ',' << p.y() << '\n';
            ++tried[std::size_t(s.goal)];
            if (s.success) ++reached[std::size_t(s.goal)], ratios[std::size_t(s.goal)].push_back(ratio);
        }
    }
    AtomicFile csv(out / "summary.csv"), md(out / "summary.md");
    csv.stream() << "world,model,goal_x,goal_y,seeds,starts,success_rate,path_ratio_median,path_ratio_q25,"
                    "path_ratio_q75,learn_h_mean\n";
    md.stream() << "# Navigation: " << world_name << ", model " << o.model << ", " << o.seeds << " learning run(s)\n\n"
                << "| goal | starts | success | path ratio median [q25, q75] (successes) | learning h (mean) |\n"
                << "|---|---|---|---|---|\n";
    for (std::size_t g = 0; g < n_goals; ++g) {
        double mean_learn = 0;
        for (double t : learn_s[g]) mean_learn += t / 3600 / double(learn_s[g].size());
        const double rate = tried[g] ? double(reached[g]) / tried[g] : 0.0;
        const double med = quantile(ratios[g], 0.5), q25 = quantile(ratios[g], 0.25), q75 = quantile(ratios[g], 0.75);
        csv.stream() << world_name << ',' << o.model << ',' << setup.goals[g].x() << ',' << setup.goals[g].y() << ','
                     << o.seeds << ',' << tried[g] << ',' << rate << ',' << med << ',' << q25 << ',' << q75 << ','
                     << mean_learn << '\n';
        char line[256];
        std::snprintf(line, sizeof line, "| (%g, %g) | %d | %.0f %% | %.2f [%.2f, %.2f] | %.2f |\n", setup.goals[g].x(),
                      setup.goals[g].y(), tried[g], 100 * rate, med, q25, q75, mean_learn);
        md.stream() << line;
    }
    for (AtomicFile* f : {&starts, &paths, &maps, &learning, &csv, &md}) f->commit();
    std::printf("wrote %s (starts.csv, summary.csv, summary.md)\n", out.string().c_str());
    if (!o.run.no_report) {
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
    cmd->add_option("--world", o->world, "World preset or YAML file (configs/worlds/nav-*.yaml)")->required();
    cmd->add_option("--tilt", o->tilt, "Tilt of the cross arena's walls, degrees");
    cmd->add_option("--lean", o->lean, "Corner the cross walls lean toward")->capture_default_str();
    cmd->add_option("--goals", o->goals, "Goals on the floor: x,y[;x,y...] (m)")->required();
    cmd->add_option("--model", o->model, "Model preset or YAML file")->capture_default_str();
    cmd->add_option("--seeds", o->seeds, "Learning runs (seeds first-seed, first-seed+1, ...)")->capture_default_str();
    cmd->add_option("--first-seed", o->first_seed, "The first seed")->check(seed_check)->capture_default_str();
    cmd->add_option("--starts", o->nav.starts, "Starts per goal")->capture_default_str();
    cmd->add_option("--max-learn-hours", o->nav.max_learn_hours, "Longest learning walk, simulated hours")
        ->capture_default_str();
    cmd->add_option("--coverage", o->nav.coverage, "Learning ends at this fraction of free 0.5 m cells visited")
        ->capture_default_str();
    cmd->add_option("--goal-visits", o->nav.goal_visits, "... and this many visits of each goal")
        ->capture_default_str();
    o->run.add_out(*cmd, "Output folder")->required();
    o->run.add_no_report(*cmd);
    cmd->callback([o] { navigate_command(*o); });
}

}  // namespace bvc3d::cli

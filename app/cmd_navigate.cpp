// bvc3d navigate: navigation to goals (docs/navigation.md): learning runs, then starts per goal, written as
// starts.csv, learning.csv, paths.csv, reward_map.csv, summary.csv/.md and figures.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <sstream>

#include "bvc3d/config/model_yaml.hpp"
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

    AtomicFile starts(out / "starts.csv"), paths(out / "paths.csv"), maps(out / "reward_map.csv"),
        learning(out / "learning.csv");
    starts.stream() << "world,model,seed,goal_x,goal_y,start_x,start_y,success,path_m,shortest_m,path_ratio,time_s\n";
    paths.stream() << "seed,start,x,y\n";
    maps.stream() << "seed,goal,x,y,reward\n";
    learning.stream() << "seed,learn_s,coverage,goal,visits,goal_cell\n";
    // Per goal: the path ratios of the successes, successes, starts, learning times.
    const std::size_t n_goals = setup.goals.size();
    std::vector<std::vector<double>> ratios(n_goals), learn_s(n_goals);
    std::vector<int> reached(n_goals, 0), tried(n_goals, 0);
    for (int k = 0; k < o.seeds; ++k) {
        const std::uint64_t seed = o.first_seed + std::uint64_t(k);
        std::fprintf(stderr, "seed %llu: learning...\n", static_cast<unsigned long long>(seed));
        const NavigationRun r = navigate(world, setup, seed);
        std::fprintf(stderr, "seed %llu: learned in %.2f h (coverage %.3f); %zu starts\n",
                     static_cast<unsigned long long>(seed), r.learn_s / 3600, r.coverage, r.starts.size());
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

#include "bvc3d/report/navigation_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"
#include "bvc3d/navigation/failure_class.hpp"

namespace bvc3d {

double quantile(std::vector<double> v, double q) {
    if (v.empty()) return std::nan("");
    std::sort(v.begin(), v.end());
    const double at = q * double(v.size() - 1);
    const auto lo = static_cast<std::size_t>(at);
    const auto hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (at - double(lo)) * (v[hi] - v[lo]);
}

namespace {

std::string num(double v) { return format_number(v); }

// "x,y" or "x,y,z" of point i of `v` (points of `dims` numbers).
std::string point(const std::vector<double>& v, std::size_t i, int dims) {
    std::string s;
    for (int d = 0; d < dims; ++d) {
        if (d) s += ',';
        s += num(v[i * std::size_t(dims) + std::size_t(d)]);
    }
    return s;
}

}  // namespace

NavigationTrial read_navigation_trial(const std::filesystem::path& file) {
    TrialNavigation read = read_trial_navigation(file);
    NavigationTrial t{read.world, read.model, read.seed, std::move(read.record)};
    for (const auto& [key, value] : read.swept) {
        if (key == "world") t.world = value;
        if (key == "model") t.model = value;
    }
    return t;
}

void write_navigation_report(const std::filesystem::path& folder, const std::vector<NavigationTrial>& trials) {
    if (trials.empty()) return;
    const int dims = trials.front().record.dims;
    for (const NavigationTrial& t : trials)
        if (t.record.dims != dims)
            throw InputError("navigation report: goals on the floor and in 3-D in one table (model " + t.model +
                             ", seed " + std::to_string(t.seed) + ")");
    const bool flying = dims == 3;
    const auto goal_of = [](const NavigationRecord& r, std::size_t g) {
        return std::vector<double>(r.goals.begin() + std::ptrdiff_t(g) * r.dims,
                                   r.goals.begin() + std::ptrdiff_t(g + 1) * r.dims);
    };

    AtomicFile starts(folder / "starts.csv"), paths(folder / "paths.csv"), maps(folder / "reward_map.csv"),
        learning(folder / "learning.csv");
    starts.stream() << "world,model,seed,goal_x,goal_y,start_x,start_y,success,path_m,shortest_m,path_ratio,time_s"
                    << (flying ? ",goal_z,start_z" : "") << ",failure\n";
    paths.stream() << "model,seed,start,x,y" << (flying ? ",z\n" : "\n");
    maps.stream() << "model,seed,goal,x,y,reward\n";
    learning.stream() << "model,seed,learn_s,coverage,goal,visits,goal_cell\n";

    // A row of the summary per world, model and goal, in the order they first appear.
    struct Cell {
        std::string world, model;
        std::vector<double> goal;
        std::vector<double> ratios, learn_s;
        int reached = 0, tried = 0, seeds = 0;
    };
    std::vector<Cell> cells;
    const auto cell_of = [&](const NavigationTrial& t, std::size_t g) -> Cell& {
        const auto goal = goal_of(t.record, g);
        for (Cell& c : cells)
            if (c.world == t.world && c.model == t.model && c.goal == goal) return c;
        return cells.emplace_back(Cell{t.world, t.model, goal, {}, {}, 0, 0, 0});
    };
    for (const NavigationTrial& t : trials) {
        const NavigationRecord& r = t.record;
        const std::string who = t.model + ',' + std::to_string(t.seed);
        for (std::size_t g = 0; g < r.n_goals(); ++g) {
            learning.stream() << who << ',' << num(r.learn_s) << ',' << num(r.coverage) << ',' << g << ','
                              << r.visits[g] << ',' << r.goal_cells[g] << '\n';
            Cell& c = cell_of(t, g);
            c.learn_s.push_back(r.learn_s);
            ++c.seeds;
            const std::size_t n_points = r.map_points.size() / 2;
            for (std::size_t k = 0; k < n_points; ++k)
                maps.stream() << who << ',' << g << ',' << point(r.map_points, k, 2) << ','
                              << num(r.map_reward[g * n_points + k]) << '\n';
        }
        for (std::size_t i = 0; i < r.n_starts(); ++i) {
            const auto g = std::size_t(r.start_goal[i]);
            const auto goal = goal_of(r, g);
            const double ratio = r.path_m[i] / r.shortest_m[i];
            starts.stream() << t.world << ',' << who << ',' << num(goal[0]) << ',' << num(goal[1]) << ','
                            << num(r.start[i * std::size_t(dims)]) << ',' << num(r.start[i * std::size_t(dims) + 1])
                            << ',' << r.success[i] << ',' << num(r.path_m[i]) << ',' << num(r.shortest_m[i]) << ','
                            << num(ratio) << ',' << num(r.time_s[i]);
            if (flying) starts.stream() << ',' << num(goal[2]) << ',' << num(r.start[i * 3 + 2]);
            // Why it failed: empty when it arrived, and in files written before the classes existed.
            starts.stream() << ',' << (i < r.failure.size() ? to_string(FailureClass(r.failure[i])) : "") << '\n';
            for (std::uint64_t k = r.path_start[i]; k < r.path_start[i + 1]; ++k)
                paths.stream() << who << ',' << i << ',' << point(r.path, k, dims) << '\n';
            Cell& c = cell_of(t, g);
            ++c.tried;
            if (r.success[i]) ++c.reached, c.ratios.push_back(ratio);
        }
    }

    AtomicFile csv(folder / "summary.csv"), md(folder / "summary.md");
    int n_seeds = 0;
    for (const Cell& c : cells) n_seeds = std::max(n_seeds, c.seeds);
    csv.stream() << "world,model,goal_x,goal_y,seeds,starts,success_rate,path_ratio_median,path_ratio_q25,"
                    "path_ratio_q75,learn_h_mean"
                 << (flying ? ",goal_z\n" : "\n");
    md.stream()
        << "# Navigation: " << trials.front().world << ", " << n_seeds << " learning run(s) per model\n\n"
        << "| model | goal | starts | success | path ratio median [q25, q75] (successes) | learning h (mean) |\n"
        << "|---|---|---|---|---|---|\n";
    for (const Cell& c : cells) {
        double mean_learn = 0;
        for (double s : c.learn_s) mean_learn += s / 3600 / double(c.learn_s.size());
        const double rate = c.tried ? double(c.reached) / c.tried : 0.0;
        const double med = quantile(c.ratios, 0.5), q25 = quantile(c.ratios, 0.25), q75 = quantile(c.ratios, 0.75);
        csv.stream() << c.world << ',' << c.model << ',' << num(c.goal[0]) << ',' << num(c.goal[1]) << ',' << c.seeds
                     << ',' << c.tried << ',' << num(rate) << ',' << num(med) << ',' << num(q25) << ',' << num(q75)
                     << ',' << num(mean_learn);
        if (flying) csv.stream() << ',' << num(c.goal[2]);
        csv.stream() << '\n';
        char where[96], line[256];
        if (flying) std::snprintf(where, sizeof where, "(%g, %g, %g)", c.goal[0], c.goal[1], c.goal[2]);
        else std::snprintf(where, sizeof where, "(%g, %g)", c.goal[0], c.goal[1]);
        std::snprintf(line, sizeof line, "| %s | %d | %.0f %% | %.2f [%.2f, %.2f] | %.2f |\n", where, c.tried,
                      100 * rate, med, q25, q75, mean_learn);
        md.stream() << "| " << c.model << (cells.front().world == c.world ? "" : " (" + c.world + ")") << " " << line;
    }
    for (AtomicFile* f : {&starts, &paths, &maps, &learning, &csv, &md}) f->commit();
}

}  // namespace bvc3d

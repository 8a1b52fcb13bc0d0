#include "bvc3d/report/navigation_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bvc3d/core/atomic_file.hpp"
#include "bvc3d/core/csv.hpp"
#include "bvc3d/core/error.hpp"
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

// The fields x, y (and z when `dims` is 3) of point i of `v` (points of `dims` numbers).
void point(CsvWriter& w, const std::vector<double>& v, std::size_t i, int dims) {
    for (int d = 0; d < dims; ++d) w.field(v[i * std::size_t(dims) + std::size_t(d)]);
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

    AtomicFile starts_file(folder / "starts.csv"), paths_file(folder / "paths.csv"),
        maps_file(folder / "reward_map.csv"), learning_file(folder / "learning.csv");
    CsvWriter starts(starts_file.stream()), paths(paths_file.stream()), maps(maps_file.stream()),
        learning(learning_file.stream());
    // A flying run (goals x,y,z) adds goal_z,start_z (before failure) to starts.csv, z to paths.csv and goal_z to
    // summary.csv.
    if (flying) {
        starts.row("world", "model", "seed", "goal_x", "goal_y", "start_x", "start_y", "success", "path_m",
                   "shortest_m", "path_ratio", "time_s", "goal_z", "start_z", "failure");
        paths.row("model", "seed", "start", "x", "y", "z");
    } else {
        starts.row("world", "model", "seed", "goal_x", "goal_y", "start_x", "start_y", "success", "path_m",
                   "shortest_m", "path_ratio", "time_s", "failure");
        paths.row("model", "seed", "start", "x", "y");
    }
    maps.row("model", "seed", "goal", "x", "y", "reward");
    learning.row("model", "seed", "learn_s", "coverage", "goal", "visits", "goal_cell");

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
        for (std::size_t g = 0; g < r.n_goals(); ++g) {
            learning.row(t.model, t.seed, r.learn_s, r.coverage, g, r.visits[g], r.goal_cells[g]);
            Cell& c = cell_of(t, g);
            c.learn_s.push_back(r.learn_s);
            ++c.seeds;
            const std::size_t n_points = r.map_points.size() / 2;
            for (std::size_t k = 0; k < n_points; ++k) {
                maps.field(t.model).field(t.seed).field(g);
                point(maps, r.map_points, k, 2);
                maps.field(r.map_reward[g * n_points + k]).end_row();
            }
        }
        for (std::size_t i = 0; i < r.n_starts(); ++i) {
            const auto g = std::size_t(r.start_goal[i]);
            const auto goal = goal_of(r, g);
            const double ratio = r.path_m[i] / r.shortest_m[i];
            starts.field(t.world).field(t.model).field(t.seed).field(goal[0]).field(goal[1]);
            starts.field(r.start[i * std::size_t(dims)]).field(r.start[i * std::size_t(dims) + 1]).field(r.success[i]);
            starts.field(r.path_m[i]).field(r.shortest_m[i]).field(ratio).field(r.time_s[i]);
            if (flying) starts.field(goal[2]).field(r.start[i * 3 + 2]);
            // Why it failed: empty when it arrived, and in files written before the classes existed.
            starts.field(i < r.failure.size() ? to_string(FailureClass(r.failure[i])) : std::string());
            starts.end_row();
            for (std::uint64_t k = r.path_start[i]; k < r.path_start[i + 1]; ++k) {
                paths.field(t.model).field(t.seed).field(i);
                point(paths, r.path, k, dims);
                paths.end_row();
            }
            Cell& c = cell_of(t, g);
            ++c.tried;
            if (r.success[i]) ++c.reached, c.ratios.push_back(ratio);
        }
    }

    AtomicFile csv_file(folder / "summary.csv"), md(folder / "summary.md");
    CsvWriter csv(csv_file.stream());
    int n_seeds = 0;
    for (const Cell& c : cells) n_seeds = std::max(n_seeds, c.seeds);
    for (const char* name : {"world", "model", "goal_x", "goal_y", "seeds", "starts", "success_rate",
                             "path_ratio_median", "path_ratio_q25", "path_ratio_q75", "learn_h_mean"})
        csv.field(name);
    if (flying) csv.field("goal_z");
    csv.end_row();
    md.stream()
        << "# Navigation: " << trials.front().world << ", " << n_seeds << " learning run(s) per model\n\n"
        << "| model | goal | starts | success | path ratio median [q25, q75] (successes) | learning h (mean) |\n"
        << "|---|---|---|---|---|---|\n";
    for (const Cell& c : cells) {
        double mean_learn = 0;
        for (double s : c.learn_s) mean_learn += s / 3600 / double(c.learn_s.size());
        const double rate = c.tried ? double(c.reached) / c.tried : 0.0;
        const double med = quantile(c.ratios, 0.5), q25 = quantile(c.ratios, 0.25), q75 = quantile(c.ratios, 0.75);
        csv.field(c.world).field(c.model).field(c.goal[0]).field(c.goal[1]).field(c.seeds).field(c.tried);
        csv.field(rate).field(med).field(q25).field(q75).field(mean_learn);
        if (flying) csv.field(c.goal[2]);
        csv.end_row();
        char where[96], line[256];
        if (flying) std::snprintf(where, sizeof where, "(%g, %g, %g)", c.goal[0], c.goal[1], c.goal[2]);
        else std::snprintf(where, sizeof where, "(%g, %g)", c.goal[0], c.goal[1]);
        std::snprintf(line, sizeof line, "| %s | %d | %.0f %% | %.2f [%.2f, %.2f] | %.2f |\n", where, c.tried,
                      100 * rate, med, q25, q75, mean_learn);
        md.stream() << "| " << c.model << (cells.front().world == c.world ? "" : " (" + c.world + ")") << " " << line;
    }
    for (AtomicFile* f : {&starts_file, &paths_file, &maps_file, &learning_file, &csv_file, &md}) f->commit();
}

}  // namespace bvc3d

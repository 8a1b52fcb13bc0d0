#include "bvc3d/agent/tour.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <unordered_map>

#include "bvc3d/agent/grid_path.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d {

const params::Table<TourParams>& TourParams::table() {
    using namespace params;
    static const Table<TourParams> t(
        "tour", {real("coverage_radius", &TourParams::coverage_radius, closed(0.2, 100),
                      "m: the tour passes within this of the walkable region"),
                 real("min_coverage", &TourParams::min_coverage, closed(0, 1),
                      "fraction of the walkable region the tour must pass near"),
                 real("margin", &TourParams::margin, closed(0, 10), "m of clearance planned beyond the body's radius"),
                 real("min_reverse", &TourParams::min_reverse, closed(0, 1e5),
                      "m driven a second time in the opposite direction, at least"),
                 real("cell", &TourParams::cell, closed(0.01, 1), "m, the free-space grid's cells")});
    return t;
}

namespace {

// The walkable region of a drive: the cells where the body fits, in the part holding `start`.
std::vector<char> walkable_cells(const FreeSpaceGrid& grid, double radius, const Vec2& start) {
    int count = 0;
    const auto label = grid.parts(radius, count);
    std::vector<char> region(grid.size(), 0);
    auto c = grid.cell_of(start);
    // The start's cell, or the nearest cell of a part within one cell.
    int mine = c ? label[grid.index(*c)] : -1;
    for (int dy = -1; mine < 0 && c && dy <= 1; ++dy)
        for (int dx = -1; mine < 0 && dx <= 1; ++dx)
            if (grid.contains({c->x + dx, c->y + dy})) mine = label[grid.index({c->x + dx, c->y + dy})];
    if (mine < 0) return region;
    for (std::size_t i = 0; i < region.size(); ++i) region[i] = label[i] == mine;
    return region;
}

RouteStats stats_on(const std::vector<ModelStep>& steps, const FreeSpaceGrid& grid, double radius,
                    const TourParams& p) {
    RouteStats s;
    if (steps.empty()) return s;
    std::vector<Vec2> path;
    for (const auto& st : steps) path.push_back(Vec2(st.pose.x, st.pose.y));
    std::vector<double> along(path.size(), 0.0);
    for (std::size_t i = 1; i < path.size(); ++i) along[i] = along[i - 1] + (path[i] - path[i - 1]).norm();
    s.length = along.back();
    s.closing_gap = (path.back() - path.front()).norm();

    // Coverage: cells within coverage_radius of a segment of the path.
    const auto region = walkable_cells(grid, radius, path.front());
    std::vector<char> covered(grid.size(), 0);
    const double R = p.coverage_radius, h = grid.cell();
    for (std::size_t i = 0; i < path.size(); ++i) {
        const Vec2 a = path[i], b = path[i + 1 < path.size() ? i + 1 : i];
        Eigen::AlignedBox2d box;
        box.extend(a);
        box.extend(b);
        const auto lo = grid.cell_of(box.min() - Vec2::Constant(R)), hi = grid.cell_of(box.max() + Vec2::Constant(R));
        const int x0 = lo ? lo->x : 0, y0 = lo ? lo->y : 0;
        const int x1 = hi ? hi->x : grid.nx() - 1, y1 = hi ? hi->y : grid.ny() - 1;
        const Vec2 ab = b - a;
        const double len2 = ab.squaredNorm();
        for (int y = std::max(0, y0); y <= std::min(grid.ny() - 1, y1); ++y)
            for (int x = std::max(0, x0); x <= std::min(grid.nx() - 1, x1); ++x) {
                const std::size_t k = grid.index({x, y});
                if (!region[k] || covered[k]) continue;
                const Vec2 c = grid.center({x, y});
                const double t = len2 > 0 ? std::clamp((c - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
                if ((c - (a + t * ab)).squaredNorm() <= R * R) covered[k] = 1;
            }
    }
    const double cells = static_cast<double>(std::count(region.begin(), region.end(), 1));
    s.walkable_area = cells * h * h;
    s.coverage = cells > 0 ? static_cast<double>(std::count(covered.begin(), covered.end(), 1)) / cells : 0.0;

    // Revisits: a step near an earlier step at least 3 m of path before it, heading opposite (or alike).
    constexpr double min_apart = 3.0;  // m of path between a place and its revisit
    const double bucket = R;
    std::unordered_map<long long, std::vector<std::size_t>> buckets;
    const auto key = [&](int bx, int by) { return (static_cast<long long>(bx) << 32) ^ static_cast<unsigned>(by); };
    std::size_t added = 0;
    for (std::size_t i = 1; i < path.size(); ++i) {
        while (added < i && along[added] <= along[i] - min_apart) {
            buckets[key(static_cast<int>(std::floor(path[added].x() / bucket)),
                        static_cast<int>(std::floor(path[added].y() / bucket)))]
                .push_back(added);
            ++added;
        }
        const int bx = static_cast<int>(std::floor(path[i].x() / bucket));
        const int by = static_cast<int>(std::floor(path[i].y() / bucket));
        bool reverse = false, same = false;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const auto it = buckets.find(key(bx + dx, by + dy));
                if (it == buckets.end()) continue;
                for (std::size_t j : it->second) {
                    if ((path[j] - path[i]).squaredNorm() > R * R) continue;
                    const double dh = std::abs(wrap_pi(steps[i].pose.heading - steps[j].pose.heading));
                    reverse = reverse || dh >= deg_to_rad(135);
                    same = same || dh <= deg_to_rad(45);
                }
            }
        const double step = along[i] - along[i - 1];
        if (reverse) s.reverse_length += step;
        if (same) s.same_length += step;
    }
    return s;
}

// Targets within `reach` (m, along the region's cells) of a cell: a bounded Dijkstra that reuses its
// buffers between calls.
class LocalReach {
public:
    LocalReach(const FreeSpaceGrid& grid, const std::vector<char>& region)
        : grid_(grid), region_(region), dist_(grid.size(), std::numeric_limits<double>::infinity()) {}

    template <class F>
    void around(GridCell from, double reach, F&& visit) {
        static constexpr int dx[8] = {1, -1, 0, 0, 1, 1, -1, -1}, dy[8] = {0, 0, 1, -1, 1, -1, 1, -1};
        using Item = std::pair<double, std::size_t>;
        std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
        const std::size_t s = grid_.index(from);
        dist_[s] = 0;
        touched_.assign(1, s);
        open.push({0.0, s});
        const double h = grid_.cell();
        while (!open.empty()) {
            const auto [d, k] = open.top();
            open.pop();
            if (d > dist_[k]) continue;
            visit(k);
            const GridCell c = grid_.cell_at(k);
            for (int i = 0; i < 8; ++i) {
                const GridCell n{c.x + dx[i], c.y + dy[i]};
                if (!grid_.contains(n) || !region_[grid_.index(n)]) continue;
                if (i >= 4 && !(region_[grid_.index({c.x + dx[i], c.y})] && region_[grid_.index({c.x, c.y + dy[i]})]))
                    continue;
                const double nd = d + (i >= 4 ? h * std::sqrt(2.0) : h);
                const std::size_t m = grid_.index(n);
                if (nd > reach || nd >= dist_[m]) continue;
                if (!std::isfinite(dist_[m])) touched_.push_back(m);
                dist_[m] = nd;
                open.push({nd, m});
            }
        }
        for (std::size_t k : touched_) dist_[k] = std::numeric_limits<double>::infinity();
    }

private:
    const FreeSpaceGrid& grid_;
    const std::vector<char>& region_;
    std::vector<double> dist_;
    std::vector<std::size_t> touched_;
};

// The usable cell nearest to p that p reaches in a straight line (within one meter), or none.
std::optional<GridCell> entry_cell(const GridPathFinder& finder, const BodyCollider& body, const Vec2& p) {
    const FreeSpaceGrid& grid = finder.grid();
    const auto c = grid.cell_of(p);
    if (!c) return std::nullopt;
    const int span = static_cast<int>(std::ceil(1.0 / grid.cell()));
    std::optional<GridCell> best;
    double best_d = std::numeric_limits<double>::infinity();
    for (int dy = -span; dy <= span; ++dy)
        for (int dx = -span; dx <= span; ++dx) {
            const GridCell n{c->x + dx, c->y + dy};
            if (!finder.usable(n)) continue;
            const double d = (grid.center(n) - p).norm();
            if (d < best_d && body.clearance(p, grid.center(n)) >= 0) {
                best_d = d;
                best = n;
            }
        }
    return best;
}

// The first `length` m of a polyline.
std::vector<Vec2> head_of(const std::vector<Vec2>& line, double length) {
    std::vector<Vec2> out{line.front()};
    for (std::size_t i = 1; i < line.size() && length > 0; ++i) {
        const double seg = (line[i] - line[i - 1]).norm();
        if (seg >= length) {
            out.push_back(line[i - 1] + (line[i] - line[i - 1]) * (length / seg));
            break;
        }
        out.push_back(line[i]);
        length -= seg;
    }
    return out;
}

}  // namespace

RouteStats route_stats(const std::vector<ModelStep>& steps, const BodyCollider& body, const TourParams& params) {
    params.validate();
    const FreeSpaceGrid grid(body, params.cell);
    return stats_on(steps, grid, body.radius(), params);
}

Tour make_tour(const WorldDescription& world, double radius, double height, std::optional<Vec2> start,
               const TourParams& params, const RouteParams& route) {
    params.validate();
    route.validate();
    const BodyCollider body(world, radius, height);
    const BodyCollider wide(world, radius + params.margin, height);  // the clearance the tour plans with
    const FreeSpaceGrid grid(body, params.cell);
    const double plan_radius = radius + params.margin;
    const GridPathFinder finder(grid, plan_radius);

    // Where it starts.
    GridCell start_cell;
    Vec2 start_point;
    if (start) {
        if (!body.is_free(*start))
            throw InputError(
                "tour start " + point_text(*start) +
                " lies inside geometry, closer than the body's radius to it, or outside the walkable region");
        const auto c = entry_cell(finder, body, *start);
        if (!c)
            throw InputError("tour start " + point_text(*start) + " has no place within 1 m clear of geometry by " +
                             format_number(plan_radius) + " m (the body's radius and the tour's margin)");
        start_cell = *c;
        start_point = *start;
    } else {
        int count = 0;
        const auto label = grid.parts(plan_radius, count);
        if (count == 0)
            throw InputError("world '" + world.name + "': no place on the floor is clear of geometry by " +
                             format_number(plan_radius) + " m (the body's radius and the tour's margin)");
        std::vector<double> size(static_cast<std::size_t>(count), 0.0);
        std::vector<Vec2> sum(static_cast<std::size_t>(count), Vec2::Zero());
        for (std::size_t i = 0; i < label.size(); ++i)
            if (label[i] >= 0) {
                size[static_cast<std::size_t>(label[i])] += 1;
                sum[static_cast<std::size_t>(label[i])] += grid.center(grid.cell_at(i));
            }
        const int big = static_cast<int>(std::max_element(size.begin(), size.end()) - size.begin());
        const Vec2 middle = sum[static_cast<std::size_t>(big)] / size[static_cast<std::size_t>(big)];
        double best = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < label.size(); ++i)
            if (label[i] == big && (grid.center(grid.cell_at(i)) - middle).squaredNorm() < best) {
                best = (grid.center(grid.cell_at(i)) - middle).squaredNorm();
                start_cell = grid.cell_at(i);
            }
        start_point = grid.center(start_cell);
    }

    // Viewpoints: greedy cover of the walkable region (targets every other cell) by candidates on a
    // lattice, each covering the targets within coverage_radius − 0.1 m along free space.
    const auto region = walkable_cells(grid, radius, start_point);
    const GridPathFinder::Reach from_start = finder.reach(start_cell);
    std::vector<std::size_t> targets, candidates;
    std::vector<int> target_of(grid.size(), -1);
    for (std::size_t i = 0; i < grid.size(); ++i) {
        const GridCell c = grid.cell_at(i);
        if (region[i] && c.x % 2 == 0 && c.y % 2 == 0) {
            target_of[i] = static_cast<int>(targets.size());
            targets.push_back(i);
        }
        if (c.x % 4 == 0 && c.y % 4 == 0 && std::isfinite(from_start.distance[i])) candidates.push_back(i);
    }
    if (targets.empty()) throw InputError("world '" + world.name + "': the tour's start has no walkable region");
    LocalReach local(grid, region);
    std::vector<std::vector<int>> covers(candidates.size());
    for (std::size_t k = 0; k < candidates.size(); ++k)
        local.around(grid.cell_at(candidates[k]), params.coverage_radius - 0.1, [&](std::size_t cell) {
            if (target_of[cell] >= 0) covers[k].push_back(target_of[cell]);
        });
    std::vector<char> covered(targets.size(), 0);
    std::size_t n_covered = 0;
    std::vector<std::size_t> viewpoints;
    // Lazy greedy: a candidate's gain only falls as others are chosen.
    std::priority_queue<std::pair<std::size_t, long long>> gains;  // (gain, -index): ties to the lower index
    for (std::size_t k = 0; k < candidates.size(); ++k) gains.push({covers[k].size(), -static_cast<long long>(k)});
    constexpr double goal = 0.98;  // beyond min_coverage: the drive's corners and smoothing lose a little
    while (!gains.empty() && n_covered < goal * static_cast<double>(targets.size())) {
        const auto [gain, neg] = gains.top();
        gains.pop();
        const auto k = static_cast<std::size_t>(-neg);
        std::size_t now = 0;
        for (int t : covers[k]) now += !covered[static_cast<std::size_t>(t)];
        if (now == 0) continue;
        if (now < gain) {
            gains.push({now, neg});
            continue;
        }
        viewpoints.push_back(candidates[k]);
        for (int t : covers[k])
            if (!covered[static_cast<std::size_t>(t)]) {
                covered[static_cast<std::size_t>(t)] = 1;
                ++n_covered;
            }
    }

    // Visit them nearest first, then come back.
    std::vector<char> pending(grid.size(), 0);
    for (std::size_t v : viewpoints) pending[v] = 1;
    // Each leg (viewpoint to viewpoint) straightened on its own: the viewpoints stay on the tour.
    std::vector<Vec2> line{start_point};
    const auto add_leg = [&](const std::vector<GridCell>& cells, const Vec2* end) {
        std::vector<Vec2> leg{line.back()};
        for (const auto& c : cells)
            if (grid.center(c) != leg.back()) leg.push_back(grid.center(c));
        if (end && *end != leg.back()) leg.push_back(*end);
        const auto straight = straighten(leg, wide);
        line.insert(line.end(), straight.begin() + 1, straight.end());
    };
    GridCell at = start_cell;
    for (std::size_t left = viewpoints.size(); left > 0; --left) {
        const auto r = finder.reach(at, [&](std::size_t cell) { return pending[cell] != 0; });
        if (r.stopped_at < 0) break;  // the rest cannot be reached
        add_leg(finder.path_to(r, static_cast<std::size_t>(r.stopped_at)), nullptr);
        pending[static_cast<std::size_t>(r.stopped_at)] = 0;
        at = grid.cell_at(static_cast<std::size_t>(r.stopped_at));
    }
    add_leg(finder.shortest_path(at, start_cell), &start_point);

    Tour tour;
    tour.waypoints = line;
    tour.steps = route_through(tour.waypoints, body, route);
    tour.stats = stats_on(tour.steps, grid, radius, params);
    if (tour.stats.reverse_length < params.min_reverse) {
        // Out along the tour's first part and back, then the tour.
        const auto out = head_of(tour.waypoints, params.min_reverse / 2 + 1.0);
        std::vector<Vec2> w = out;
        w.insert(w.end(), out.rbegin() + 1, out.rend());
        w.insert(w.end(), tour.waypoints.begin() + 1, tour.waypoints.end());
        tour.waypoints = w;
        tour.steps = route_through(tour.waypoints, body, route);
        tour.stats = stats_on(tour.steps, grid, radius, params);
    }
    if (tour.stats.coverage < params.min_coverage)
        throw InputError("the tour of world '" + world.name + "' passes within " +
                         format_number(params.coverage_radius) + " m of only " +
                         format_number(std::round(tour.stats.coverage * 1000) / 10) + " % of the walkable region (" +
                         format_number(params.min_coverage * 100) + " % asked): the rest is out of reach with " +
                         format_number(plan_radius) + " m of clearance");
    return tour;
}

}  // namespace bvc3d

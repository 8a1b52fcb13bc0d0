#include "bvc3d/agent/grid_path.hpp"

#include <cmath>
#include <limits>
#include <queue>

namespace bvc3d {

namespace {

constexpr int dx8[8] = {1, -1, 0, 0, 1, 1, -1, -1};
constexpr int dy8[8] = {0, 0, 1, -1, 1, -1, 1, -1};

struct Open {
    double key;
    std::size_t cell;
    bool operator>(const Open& o) const { return key > o.key || (key == o.key && cell > o.cell); }
};
using Heap = std::priority_queue<Open, std::vector<Open>, std::greater<Open>>;

}  // namespace

GridPathFinder::GridPathFinder(const FreeSpaceGrid& grid, double radius) : grid_(grid), radius_(radius) {}

std::vector<GridCell> GridPathFinder::shortest_path(GridCell from, GridCell to) const {
    if (!usable(from) || !usable(to)) return {};
    const double h = grid_.cell();
    const auto octile = [&](GridCell a) {
        const double ax = std::abs(a.x - to.x), ay = std::abs(a.y - to.y);
        return h * (std::max(ax, ay) + (std::sqrt(2.0) - 1) * std::min(ax, ay));
    };
    std::vector<double> g(grid_.size(), std::numeric_limits<double>::infinity());
    std::vector<int> parent(grid_.size(), -1);
    std::vector<char> closed(grid_.size(), 0);
    Heap open;
    g[grid_.index(from)] = 0;
    open.push({octile(from), grid_.index(from)});
    const std::size_t goal = grid_.index(to);
    while (!open.empty()) {
        const Open top = open.top();
        open.pop();
        if (closed[top.cell]) continue;
        closed[top.cell] = 1;
        if (top.cell == goal) break;
        const GridCell c = grid_.cell_at(top.cell);
        for (int d = 0; d < 8; ++d) {
            const GridCell n{c.x + dx8[d], c.y + dy8[d]};
            if (!usable(n)) continue;
            if (d >= 4 && !(usable({c.x + dx8[d], c.y}) && usable({c.x, c.y + dy8[d]}))) continue;
            const std::size_t k = grid_.index(n);
            const double step = d >= 4 ? h * std::sqrt(2.0) : h;
            if (closed[k] || g[top.cell] + step >= g[k]) continue;
            g[k] = g[top.cell] + step;
            parent[k] = static_cast<int>(top.cell);
            open.push({g[k] + octile(n), k});
        }
    }
    if (!closed[goal]) return {};
    std::vector<GridCell> path;
    for (int k = static_cast<int>(goal); k >= 0; k = parent[static_cast<std::size_t>(k)])
        path.push_back(grid_.cell_at(static_cast<std::size_t>(k)));
    return {path.rbegin(), path.rend()};
}

GridPathFinder::Reach GridPathFinder::reach(GridCell from, const std::function<bool(std::size_t)>& stop,
                                            double max_distance) const {
    Reach r;
    r.distance.assign(grid_.size(), std::numeric_limits<float>::infinity());
    r.parent.assign(grid_.size(), -1);
    if (!usable(from)) return r;
    const double h = grid_.cell();
    std::vector<double> g(grid_.size(), std::numeric_limits<double>::infinity());
    std::vector<char> closed(grid_.size(), 0);
    Heap open;
    g[grid_.index(from)] = 0;
    open.push({0.0, grid_.index(from)});
    while (!open.empty()) {
        const Open top = open.top();
        open.pop();
        if (closed[top.cell]) continue;
        if (top.key > max_distance) break;
        closed[top.cell] = 1;
        r.distance[top.cell] = static_cast<float>(top.key);
        if (stop && stop(top.cell)) {
            r.stopped_at = static_cast<long long>(top.cell);
            break;
        }
        const GridCell c = grid_.cell_at(top.cell);
        for (int d = 0; d < 8; ++d) {
            const GridCell n{c.x + dx8[d], c.y + dy8[d]};
            if (!usable(n)) continue;
            if (d >= 4 && !(usable({c.x + dx8[d], c.y}) && usable({c.x, c.y + dy8[d]}))) continue;
            const std::size_t k = grid_.index(n);
            const double step = d >= 4 ? h * std::sqrt(2.0) : h;
            if (closed[k] || g[top.cell] + step >= g[k]) continue;
            g[k] = g[top.cell] + step;
            r.parent[k] = static_cast<int>(top.cell);
            open.push({g[k], k});
        }
    }
    return r;
}

std::vector<GridCell> GridPathFinder::path_to(const Reach& r, std::size_t to) const {
    std::vector<GridCell> path;
    if (!std::isfinite(r.distance[to])) return path;
    for (int k = static_cast<int>(to); k >= 0; k = r.parent[static_cast<std::size_t>(k)])
        path.push_back(grid_.cell_at(static_cast<std::size_t>(k)));
    return {path.rbegin(), path.rend()};
}

std::vector<Vec2> straighten(const std::vector<Vec2>& points, const BodyCollider& body) {
    if (points.size() <= 2) return points;
    const auto clear = [&](const Vec2& a, const Vec2& b) {
        const double len = (b - a).norm();
        return len == 0.0 || body.free_distance(a, (b - a) / len, len) >= len;
    };
    std::vector<Vec2> out{points.front()};
    std::size_t from = 0;
    while (from + 1 < points.size()) {
        // The farthest point reachable in a straight line, found by doubling then halving the step.
        std::size_t good = from + 1, step = 1;
        while (good + step < points.size() && clear(points[from], points[good + step])) {
            good += step;
            step *= 2;
        }
        for (step /= 2; step > 0; step /= 2)
            if (good + step < points.size() && clear(points[from], points[good + step])) good += step;
        out.push_back(points[good]);
        from = good;
    }
    return out;
}

}  // namespace bvc3d

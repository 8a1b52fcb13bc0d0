#include "bvc3d/agent/authors_grid.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d {

namespace {

double nanometre(double v) { return std::round(v * 1e9) / 1e9; }

// Distance from p to the polygon's boundary.
double boundary_distance(const Polygon2& poly, const Vec2& p) {
    double best = std::numeric_limits<double>::infinity();
    const auto& w = poly.points;
    for (std::size_t i = 0; i < w.size(); ++i) {
        const Vec2 a = w[i], b = w[(i + 1) % w.size()], ab = b - a;
        const double len2 = ab.squaredNorm();
        const double t = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
        best = std::min(best, (p - (a + t * ab)).norm());
    }
    return best;
}

}  // namespace

AuthorsGrid::AuthorsGrid(const BodyCollider& body, double cell, double inflate) : cell_(cell) {
    if (!(cell > 0) || !(inflate >= 0)) throw InputError("the authors' grid: cell > 0 and inflate >= 0");
    const auto bounds = body.walkable().bounds();
    west_ = std::floor(bounds.min().x()), east_ = std::ceil(bounds.max().x());
    south_ = std::floor(bounds.min().y()), north_ = std::ceil(bounds.max().y());
    cols_ = static_cast<int>(std::lround((east_ - west_) / cell));
    rows_ = static_cast<int>(std::lround((north_ - south_) / cell));
    if (double(cols_) * rows_ > 1e8)
        throw InputError("the authors' grid: " + format_number(double(cols_) * rows_) + " cells of " +
                         format_number(cell) + " m is too many");
    blocked_.assign(std::size_t(cols_) * std::size_t(rows_), 0);
    for (const Segment2& s : body.segments()) {
        // The walls that bound the floor are not the planner's obstacles: only geometry inside the walkable region.
        const Vec2 mid = (s.a + s.b) / 2;
        if (!body.walkable().contains(mid) || boundary_distance(body.walkable(), mid) < 1e-9) continue;
        block_segment(s, inflate);
    }
}

void AuthorsGrid::block_segment(const Segment2& s, double inflate) {
    const Vec2 a(nanometre(s.a.x()), nanometre(s.a.y())), b(nanometre(s.b.x()), nanometre(s.b.y()));
    // A point without a radius is a polygon's corner (a vertical edge), whose sides are segments of their own: it adds
    // nothing to them (and has no frame). A sphere's disc is a point with a radius: a square of it grown.
    if (a == b && s.radius == 0) return;
    const double grow = inflate + s.radius;
    if (a.x() == b.x() || a.y() == b.y()) {
        // Their rectangle rule on the segment's box grown by `grow`: the index ranges of both ends, clamped.
        const double x0 = std::min(a.x(), b.x()) - grow, x1 = std::max(a.x(), b.x()) + grow;
        const double y0 = std::min(a.y(), b.y()) - grow, y1 = std::max(a.y(), b.y()) + grow;
        const int c0 = std::max(0, static_cast<int>((x0 - west_) / cell_));
        const int c1 = std::min(cols_ - 1, static_cast<int>((x1 - west_) / cell_));
        const int r0 = std::max(0, static_cast<int>((north_ - y1) / cell_));
        const int r1 = std::min(rows_ - 1, static_cast<int>((north_ - y0) / cell_));
        for (int r = r0; r <= r1; ++r)
            for (int c = c0; c <= c1; ++c) blocked_[std::size_t(r) * std::size_t(cols_) + std::size_t(c)] = 1;
        return;
    }
    // At an angle: centres within the segment's rectangle grown by `grow`, in its own frame.
    const Vec2 mid = (a + b) / 2, along = (b - a).normalized(), across(-along.y(), along.x());
    const double half = (b - a).norm() / 2 + grow;
    const double reach = half + grow;
    const int c0 = std::max(0, static_cast<int>((mid.x() - reach - west_) / cell_) - 1);
    const int c1 = std::min(cols_ - 1, static_cast<int>((mid.x() + reach - west_) / cell_) + 1);
    const int r0 = std::max(0, static_cast<int>((north_ - mid.y() - reach) / cell_) - 1);
    const int r1 = std::min(rows_ - 1, static_cast<int>((north_ - mid.y() + reach) / cell_) + 1);
    for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) {
            const Vec2 d = centre(c, r) - mid;
            if (std::abs(d.dot(along)) <= half && std::abs(d.dot(across)) <= grow)
                blocked_[std::size_t(r) * std::size_t(cols_) + std::size_t(c)] = 1;
        }
}

std::optional<std::pair<int, int>> AuthorsGrid::cell_of(const Vec2& p) const {
    const double x = (p.x() - west_) / cell_, y = (north_ - p.y()) / cell_;
    if (!(x >= 0) || !(y >= 0)) return std::nullopt;
    const int c = static_cast<int>(x), r = static_cast<int>(y);
    if (c >= cols_ || r >= rows_) return std::nullopt;
    return std::pair{c, r};
}

Vec2 AuthorsGrid::centre(int col, int row) const {
    // Their expressions: col·cell − W/2 + cell/2 and −(row·cell − H/2 + cell/2), with −W/2 the west edge.
    return {col * cell_ + west_ + cell_ / 2, -(row * cell_ - north_ + cell_ / 2)};
}

std::optional<AuthorsGrid::Path> AuthorsGrid::shortest(const Vec2& from, const Vec2& goal, double radius) const {
    const auto start = cell_of(from);
    if (!start || blocked(start->first, start->second)) return std::nullopt;
    const std::size_t n = blocked_.size();
    std::vector<double> dist(n, std::numeric_limits<double>::infinity());
    std::vector<std::int64_t> parent(n, -1);
    using Item = std::pair<double, std::size_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
    const auto index = [&](int c, int r) { return std::size_t(r) * std::size_t(cols_) + std::size_t(c); };
    const std::size_t s0 = index(start->first, start->second);
    dist[s0] = 0;
    heap.push({0.0, s0});
    const double diagonal = cell_ * std::sqrt(2.0);
    while (!heap.empty()) {
        const auto [d, i] = heap.top();
        heap.pop();
        if (d > dist[i]) continue;
        const int c = static_cast<int>(i % std::size_t(cols_)), r = static_cast<int>(i / std::size_t(cols_));
        const Vec2 at = centre(c, r);
        if (std::hypot(at.x() - goal.x(), at.y() - goal.y()) <= radius) {
            Path path{d, {}};
            for (std::int64_t k = std::int64_t(i); k >= 0; k = parent[std::size_t(k)])
                path.cells.emplace_back(int(std::size_t(k) % std::size_t(cols_)),
                                        int(std::size_t(k) / std::size_t(cols_)));
            std::reverse(path.cells.begin(), path.cells.end());
            return path;
        }
        for (int dc = -1; dc <= 1; ++dc)
            for (int dr = -1; dr <= 1; ++dr) {
                if (!dc && !dr) continue;
                const int cn = c + dc, rn = r + dr;
                if (cn < 0 || rn < 0 || cn >= cols_ || rn >= rows_ || blocked(cn, rn)) continue;
                const double via = d + (dc && dr ? diagonal : cell_);
                const std::size_t j = index(cn, rn);
                if (via < dist[j]) {
                    dist[j] = via;
                    parent[j] = std::int64_t(i);
                    heap.push({via, j});
                }
            }
    }
    return std::nullopt;
}

Vec2 AuthorsGrid::draw_start(Rng& rng, const BodyCollider& body, const Vec2& goal, double min_distance, double margin,
                             double radius) const {
    for (int tries = 0; tries < 100000; ++tries) {
        const double x = rng.uniform(west_ + margin, east_ - margin);
        const double y = rng.uniform(south_ + margin, north_ - margin);
        const Vec2 p(x, y);
        const auto c = cell_of(p);
        if (!c || blocked(c->first, c->second) || (p - goal).norm() < min_distance) continue;
        const Vec2 at = centre(c->first, c->second);
        if (!body.walkable().contains(at) || body.clearance(at) < 0.05 || !shortest(at, goal, radius)) continue;
        return at;
    }
    throw InputError("navigation: no start at least " + format_number(min_distance) + " m from the goal (" +
                     format_number(goal.x()) + ", " + format_number(goal.y()) + ") on the authors' grid");
}

}  // namespace bvc3d

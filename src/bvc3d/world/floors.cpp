#include "bvc3d/world/floors.hpp"

#include <algorithm>
#include <cmath>

#include "bvc3d/core/angles.hpp"

namespace bvc3d {

namespace {

bool horizontal(const std::array<Vec3, 3>& c, double max_tilt_deg, double* area = nullptr) {
    const Vec3 n = (c[1] - c[0]).cross(c[2] - c[0]);
    const double len = n.norm();
    if (area) *area = 0.5 * len;
    return len > 1e-12 && std::abs(n.z()) >= std::cos(deg_to_rad(max_tilt_deg)) * len;
}

// Whether p lies in the xy projection of triangle (a, b, c), edges included.
bool inside(const Vec2& p, const Vec2& a, const Vec2& b, const Vec2& c) {
    const auto side = [](const Vec2& o, const Vec2& u, const Vec2& q) {
        return (u.x() - o.x()) * (q.y() - o.y()) - (u.y() - o.y()) * (q.x() - o.x());
    };
    const double d1 = side(a, b, p), d2 = side(b, c, p), d3 = side(c, a, p);
    const bool neg = d1 < 0 || d2 < 0 || d3<0, pos = d1> 0 || d2 > 0 || d3 > 0;
    return !(neg && pos);
}

}  // namespace

std::vector<FloorLevel> floor_levels(const TriangleMesh& mesh, const std::vector<char>& skip,
                                     const FloorOptions& options) {
    struct Flat {
        double lo, hi, area;
    };
    std::vector<Flat> flats;
    for (std::size_t t = 0; t < mesh.size(); ++t) {
        if (!skip.empty() && skip[t]) continue;
        const auto c = mesh.corners(t);
        double area = 0;
        if (!horizontal(c, options.max_tilt_deg, &area)) continue;
        flats.push_back({std::min({c[0].z(), c[1].z(), c[2].z()}), std::max({c[0].z(), c[1].z(), c[2].z()}), area});
    }
    std::sort(flats.begin(), flats.end(), [](const Flat& a, const Flat& b) { return a.hi < b.hi; });
    std::vector<FloorLevel> levels;
    double group_lo = 0;
    for (std::size_t i = 0; i < flats.size();) {
        // A group: every triangle whose top is within `thickness` of the group's first top.
        FloorLevel level;
        group_lo = flats[i].hi;
        std::size_t j = i;
        for (; j < flats.size() && flats[j].hi <= group_lo + options.thickness; ++j) level.area += flats[j].area;
        // The level's height: where most of its area is (a carpet or a low shelf on a floor is not
        // the floor), to the millimeter; its highest top there.
        double best_area = -1;
        for (std::size_t a = i; a < j;) {
            std::size_t b = a;
            double area = 0;
            for (; b < j && flats[b].hi <= flats[a].hi + 1e-3; ++b) area += flats[b].area;
            if (area > best_area) {
                best_area = area;
                level.z = flats[b - 1].hi;
            }
            a = b;
        }
        if (level.area >= options.min_area) levels.push_back(level);
        i = j;
    }
    return levels;
}

bool FloorMap::holds(const Vec2& p) const {
    const int x = static_cast<int>(std::floor((p.x() - box.min().x()) / cell));
    const int y = static_cast<int>(std::floor((p.y() - box.min().y()) / cell));
    return x >= 0 && y >= 0 && x < nx && y < ny && held[static_cast<std::size_t>(y) * nx + x];
}

Eigen::AlignedBox2d FloorMap::held_bounds() const {
    Eigen::AlignedBox2d b;
    for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x)
            if (held[static_cast<std::size_t>(y) * nx + x]) {
                b.extend(box.min() + Vec2(x * cell, y * cell));
                b.extend(box.min() + Vec2((x + 1) * cell, (y + 1) * cell));
            }
    return b;
}

double FloorMap::held_area() const {
    return static_cast<double>(std::count(held.begin(), held.end(), 1)) * cell * cell;
}

FloorMap floor_map(const TriangleMesh& mesh, double cell, const FloorOptions& options) {
    FloorMap map;
    std::vector<std::size_t> floor;
    Eigen::AlignedBox2d extent;
    constexpr double rounding = 1e-6;  // m: floors a rounding error above z = 0 are still at 0
    for (std::size_t t = 0; t < mesh.size(); ++t) {
        const auto c = mesh.corners(t);
        bool level = true;
        for (const auto& v : c) level = level && v.z() <= rounding && v.z() >= -options.thickness;
        if (!level || !horizontal(c, options.max_tilt_deg)) continue;
        floor.push_back(t);
        for (const auto& v : c) extent.extend(v.head<2>());
    }
    if (floor.empty()) return map;
    // Whole cells with one spare around, so that every edge lies inside the grid; at most 2e7 cells.
    while ((extent.sizes().x() / cell + 3) * (extent.sizes().y() / cell + 3) > 2e7) cell *= 2;
    map.cell = cell;
    map.box.extend(
        Vec2((std::floor(extent.min().x() / cell) - 1) * cell, (std::floor(extent.min().y() / cell) - 1) * cell));
    map.box.extend(
        Vec2((std::ceil(extent.max().x() / cell) + 1) * cell, (std::ceil(extent.max().y() / cell) + 1) * cell));
    map.nx = static_cast<int>(std::lround(map.box.sizes().x() / cell));
    map.ny = static_cast<int>(std::lround(map.box.sizes().y() / cell));
    map.held.assign(static_cast<std::size_t>(map.nx) * map.ny, 0);
    const Vec2 origin = map.box.min();
    for (std::size_t t : floor) {
        const auto c = mesh.corners(t);
        const Vec2 a = c[0].head<2>(), b = c[1].head<2>(), d = c[2].head<2>();
        Eigen::AlignedBox2d tb;
        for (const auto& v : {a, b, d}) tb.extend(v);
        const int x0 = std::max(0, static_cast<int>(std::floor((tb.min().x() - origin.x()) / cell - 0.5)));
        const int x1 = std::min(map.nx - 1, static_cast<int>(std::ceil((tb.max().x() - origin.x()) / cell - 0.5)));
        const int y0 = std::max(0, static_cast<int>(std::floor((tb.min().y() - origin.y()) / cell - 0.5)));
        const int y1 = std::min(map.ny - 1, static_cast<int>(std::ceil((tb.max().y() - origin.y()) / cell - 0.5)));
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                char& h = map.held[static_cast<std::size_t>(y) * map.nx + x];
                if (!h && inside(origin + Vec2((x + 0.5) * cell, (y + 0.5) * cell), a, b, d)) h = 1;
            }
    }
    // The boundary between held and empty cells, as runs along each grid line.
    const auto held = [&](int x, int y) {
        return x >= 0 && y >= 0 && x < map.nx && y < map.ny && map.held[static_cast<std::size_t>(y) * map.nx + x];
    };
    for (int x = 0; x <= map.nx; ++x)  // vertical lines: between cells x-1 and x
        for (int y = 0; y < map.ny;) {
            if (held(x - 1, y) == held(x, y)) {
                ++y;
                continue;
            }
            int end = y;
            while (end < map.ny && held(x - 1, end) != held(x, end)) ++end;
            map.edges.push_back({origin + Vec2(x * cell, y * cell), origin + Vec2(x * cell, end * cell)});
            y = end;
        }
    for (int y = 0; y <= map.ny; ++y)  // horizontal lines: between cells y-1 and y
        for (int x = 0; x < map.nx;) {
            if (held(x, y - 1) == held(x, y)) {
                ++x;
                continue;
            }
            int end = x;
            while (end < map.nx && held(end, y - 1) != held(end, y)) ++end;
            map.edges.push_back({origin + Vec2(x * cell, y * cell), origin + Vec2(end * cell, y * cell)});
            x = end;
        }
    return map;
}

}  // namespace bvc3d

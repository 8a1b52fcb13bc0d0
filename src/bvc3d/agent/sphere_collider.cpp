#include "bvc3d/agent/sphere_collider.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/format.hpp"

namespace bvc3d {

namespace {

// Earliest t in [0, max_t] at which the point p + t·u (u a unit vector) comes within R of the
// segment ab's line, inside the segment; max_t if never. Only entries from outside count (the
// caller has checked that p is at least R from the triangle).
double edge_entry(const Vec3& p, const Vec3& u, double R, const Vec3& a, const Vec3& b, double max_t) {
    const Vec3 e = b - a;
    const double len2 = e.squaredNorm();
    if (len2 == 0) return max_t;
    const Vec3 w = p - a;
    const Vec3 u_perp = u - (u.dot(e) / len2) * e;
    const Vec3 w_perp = w - (w.dot(e) / len2) * e;
    const double A = u_perp.squaredNorm(), B = w_perp.dot(u_perp), C = w_perp.squaredNorm() - R * R;
    if (!(A > 0) || B >= 0) return max_t;  // moving along the edge, or away from its line
    const double disc = B * B - A * C;
    if (disc < 0) return max_t;
    const double t = C / (std::sqrt(disc) - B);  // the smaller root, without cancellation
    if (!(t >= 0) || t >= max_t) return max_t;
    const double lam = (w + t * u).dot(e) / len2;
    return lam >= 0.0 && lam <= 1.0 ? t : max_t;
}

// Earliest t in [0, max_t] at which p + t·u comes within R of the point c; max_t if never.
double vertex_entry(const Vec3& p, const Vec3& u, double R, const Vec3& c, double max_t) {
    const Vec3 w = p - c;
    const double b = w.dot(u), cc = w.squaredNorm() - R * R;
    if (b >= 0) return max_t;
    const double disc = b * b - cc;
    if (disc < 0) return max_t;
    const double t = cc / (std::sqrt(disc) - b);
    return t >= 0 && t < max_t ? t : max_t;
}

// q lies in triangle abc (q in its plane, normal n), edges included.
bool in_triangle(const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& n) {
    return n.dot((b - a).cross(q - a)) >= 0 && n.dot((c - b).cross(q - b)) >= 0 && n.dot((a - c).cross(q - c)) >= 0;
}

}  // namespace

Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const Vec3 bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
    const Vec3 cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    const double denom = 1.0 / (va + vb + vc);
    return a + ab * (vb * denom) + ac * (vc * denom);
}

SphereCollider::SphereCollider(const WorldDescription& world, double radius) : radius_(radius) {
    if (!(radius > 0) || !std::isfinite(radius)) throw InputError("the flying body's radius must be a positive number");
    if (!world.flight)
        throw InputError("world '" + world.name +
                         "' declares no flight volume: a flying agent needs one "
                         "(flight_volume in the world's YAML; docs/flying.md#worlds)");
    volume_ = *world.flight;
    const auto& region = volume_.region;
    if (region.points.size() < 3 || region.area() <= 0)
        throw InputError("world '" + world.name +
                         "': the flight volume's region needs at least 3 points and a positive area");
    const double R = radius_;
    const auto box = volume_.bounds();
    const double height = volume_.z_max - volume_.z_min;
    if (!(height >= 2 * R) || !(box.sizes().x() >= 2 * R) || !(box.sizes().y() >= 2 * R))
        throw InputError("world '" + world.name + "': the flight volume (" + format_number(box.sizes().x()) + " × " +
                         format_number(box.sizes().y()) + " × " + format_number(height) +
                         " m) is smaller than the body (a sphere of diameter " + format_number(2 * R) + " m)");
    center_box_ = Eigen::AlignedBox3d(box.min() + Vec3::Constant(R), box.max() - Vec3::Constant(R));

    // The world's triangles that a body inside the volume could touch.
    Eigen::AlignedBox3d reach(box.min() - Vec3::Constant(2 * R), box.max() + Vec3::Constant(2 * R));
    for (std::size_t t = 0; t < world.mesh.size(); ++t) {
        const auto c = world.mesh.corners(t);
        Eigen::AlignedBox3d tb;
        for (const auto& v : c) tb.extend(v);
        if (tb.intersects(reach)) add_triangle(c[0], c[1], c[2]);
    }
    // The volume's boundary: a vertical wall over each region edge reaching past floor and ceiling
    // (no center inside the volume comes near its top or bottom edge, so it acts as an infinite
    // wall), and the floor and ceiling planes over the region's bounds widened beyond those walls.
    const double lo = volume_.z_min - R - 1.0, hi = volume_.z_max + R + 1.0;
    const auto& pts = region.points;
    for (std::size_t i = 0; i < pts.size(); ++i) {
        const Vec2& a = pts[i];
        const Vec2& b = pts[(i + 1) % pts.size()];
        if ((a - b).squaredNorm() == 0) continue;
        add_triangle(Vec3(a.x(), a.y(), lo), Vec3(b.x(), b.y(), lo), Vec3(b.x(), b.y(), hi));
        add_triangle(Vec3(a.x(), a.y(), lo), Vec3(b.x(), b.y(), hi), Vec3(a.x(), a.y(), hi));
    }
    const double x0 = box.min().x() - 1, x1 = box.max().x() + 1, y0 = box.min().y() - 1, y1 = box.max().y() + 1;
    for (const double z : {volume_.z_min, volume_.z_max}) {
        add_triangle(Vec3(x0, y0, z), Vec3(x1, y0, z), Vec3(x1, y1, z));
        add_triangle(Vec3(x0, y0, z), Vec3(x1, y1, z), Vec3(x0, y1, z));
    }

    // Grid cells about twice the body's size: a move query touches a handful of them.
    for (const auto& t : triangles_) bounds_.extend(t.a), bounds_.extend(t.b), bounds_.extend(t.c);
    cell_ = std::max(4.0 * R, 1e-3);
    auto size_grid = [&] {
        for (int d = 0; d < 3; ++d) n_[d] = std::max(1, static_cast<int>(std::ceil(bounds_.sizes()[d] / cell_)));
    };
    size_grid();
    while (static_cast<double>(n_[0]) * n_[1] * n_[2] > 4e6) {  // keep the grid's memory bounded
        cell_ *= 2;
        size_grid();
    }
    grid_.assign(static_cast<std::size_t>(n_[0]) * n_[1] * n_[2], {});
    for (std::size_t i = 0; i < triangles_.size(); ++i) {
        const auto& t = triangles_[i];
        Eigen::AlignedBox3d tb;
        tb.extend(t.a), tb.extend(t.b), tb.extend(t.c);
        std::array<int, 3> c0{}, c1{};
        for (int d = 0; d < 3; ++d) {
            c0[d] = std::clamp(static_cast<int>((tb.min()[d] - bounds_.min()[d]) / cell_), 0, n_[d] - 1);
            c1[d] = std::clamp(static_cast<int>((tb.max()[d] - bounds_.min()[d]) / cell_), 0, n_[d] - 1);
        }
        for (int z = c0[2]; z <= c1[2]; ++z)
            for (int y = c0[1]; y <= c1[1]; ++y)
                for (int x = c0[0]; x <= c1[0]; ++x)
                    grid_[(static_cast<std::size_t>(z) * n_[1] + y) * n_[0] + x].push_back(static_cast<int>(i));
    }
    stamp_.assign(triangles_.size(), 0);
}

void SphereCollider::add_triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
    const Vec3 n = (b - a).cross(c - a);
    if (n.squaredNorm() == 0) return;  // degenerate: its edges belong to its neighbors
    triangles_.push_back({a, b, c, n.normalized()});
}

template <class F>
void SphereCollider::for_triangles_near(const Eigen::AlignedBox3d& box, F&& f) const {
    if (++epoch_ == 0) {
        std::fill(stamp_.begin(), stamp_.end(), 0u);
        epoch_ = 1;
    }
    std::array<int, 3> c0{}, c1{};
    for (int d = 0; d < 3; ++d) {
        c0[d] = std::clamp(static_cast<int>(std::floor((box.min()[d] - bounds_.min()[d]) / cell_)), 0, n_[d] - 1);
        c1[d] = std::clamp(static_cast<int>(std::floor((box.max()[d] - bounds_.min()[d]) / cell_)), 0, n_[d] - 1);
    }
    for (int z = c0[2]; z <= c1[2]; ++z)
        for (int y = c0[1]; y <= c1[1]; ++y)
            for (int x = c0[0]; x <= c1[0]; ++x)
                for (int i : grid_[(static_cast<std::size_t>(z) * n_[1] + y) * n_[0] + x])
                    if (stamp_[i] != epoch_) {
                        stamp_[i] = epoch_;
                        f(i);
                    }
}

double SphereCollider::free_distance(const Vec3& p, const Vec3& u, double max_dist) const {
    const double R = radius_;
    Eigen::AlignedBox3d box;
    box.extend(p);
    box.extend(p + max_dist * u);
    box.min().array() -= R;
    box.max().array() += R;
    double best = max_dist;
    for_triangles_near(box, [&](int i) {
        const Triangle& tr = triangles_[i];
        // Already touching (within R): blocked if moving closer, free if not (the distance to a
        // convex set along a line is convex, so moving away it never shrinks again).
        const Vec3 q = closest_point_on_triangle(p, tr.a, tr.b, tr.c);
        const Vec3 away = p - q;
        if (away.squaredNorm() < R * R) {
            if (away.dot(u) < 0) best = 0;
            return;
        }
        // The face, shifted by R toward p.
        Vec3 n = tr.n;
        double s0 = n.dot(p - tr.a);
        if (s0 < 0) n = -n, s0 = -s0;
        const double approach = -n.dot(u);
        if (approach > 0 && s0 >= R) {
            const double t = (s0 - R) / approach;
            if (t < best && in_triangle(p + t * u - R * n, tr.a, tr.b, tr.c, tr.n)) best = t;
        }
        best = std::min({best, edge_entry(p, u, R, tr.a, tr.b, best), edge_entry(p, u, R, tr.b, tr.c, best),
                         edge_entry(p, u, R, tr.c, tr.a, best)});
        best = std::min({best, vertex_entry(p, u, R, tr.a, best), vertex_entry(p, u, R, tr.b, best),
                         vertex_entry(p, u, R, tr.c, best)});
    });
    return std::max(best, 0.0);
}

double SphereCollider::clearance(const Vec3& p) const {
    // Grow the search box until it holds a triangle, then check everything that could be closer.
    double best = std::numeric_limits<double>::infinity();
    for (double reach = cell_;; reach *= 2) {
        const Eigen::AlignedBox3d box(p - Vec3::Constant(reach), p + Vec3::Constant(reach));
        for_triangles_near(box, [&](int i) {
            const Triangle& t = triangles_[i];
            best = std::min(best, (p - closest_point_on_triangle(p, t.a, t.b, t.c)).norm());
        });
        if (best <= reach || reach > 2 * (bounds_.sizes().norm() + (p - bounds_.center()).norm())) break;
    }
    return best - radius_;
}

bool SphereCollider::touches_any(const Vec3& p) const {
    const double R = radius_;
    bool hit = false;
    const Eigen::AlignedBox3d box(p - Vec3::Constant(R), p + Vec3::Constant(R));
    for_triangles_near(box, [&](int i) {
        if (hit) return;
        const Triangle& t = triangles_[i];
        hit = (p - closest_point_on_triangle(p, t.a, t.b, t.c)).squaredNorm() < R * R;
    });
    return hit;
}

bool SphereCollider::is_free(const Vec3& p) const {
    return p.z() >= center_box_.min().z() && p.z() <= center_box_.max().z() && volume_.region.contains(p.head<2>()) &&
           !touches_any(p);
}

double SphereCollider::free_space_step() const { return std::clamp(radius_ / 2, 0.02, 0.25); }

const SphereCollider::FreeSpace& SphereCollider::free_space() const {
    std::call_once(free_once_, [this] {
        FreeSpace& f = free_;
        f.step = free_space_step();
        for (int d = 0; d < 3; ++d) f.n[d] = std::max(1, static_cast<int>(std::ceil(center_box_.sizes()[d] / f.step)));
        while (static_cast<double>(f.n[0]) * f.n[1] * f.n[2] > 8e6) {  // bounded memory for huge volumes
            f.step *= 2;
            for (int d = 0; d < 3; ++d)
                f.n[d] = std::max(1, static_cast<int>(std::ceil(center_box_.sizes()[d] / f.step)));
        }
        // Cells centered in the center box (which may be thinner than a step).
        for (int d = 0; d < 3; ++d) f.origin[d] = center_box_.center()[d] - 0.5 * f.n[d] * f.step;
        const auto center = [&](int i, int j, int k) {
            return Vec3(f.origin.x() + (i + 0.5) * f.step, f.origin.y() + (j + 0.5) * f.step,
                        f.origin.z() + (k + 0.5) * f.step);
        };
        const std::size_t total = static_cast<std::size_t>(f.n[0]) * f.n[1] * f.n[2];
        auto index = [&](int i, int j, int k) { return (static_cast<std::size_t>(k) * f.n[1] + j) * f.n[0] + i; };
        std::vector<char> clear(total);
        for (int k = 0; k < f.n[2]; ++k)
            for (int j = 0; j < f.n[1]; ++j)
                for (int i = 0; i < f.n[0]; ++i) clear[index(i, j, k)] = is_free(center(i, j, k));
        // Flood fill over moves between neighboring centers that the body can make.
        f.label.assign(total, -1);
        std::vector<std::size_t> stack;
        const int di[6] = {1, -1, 0, 0, 0, 0}, dj[6] = {0, 0, 1, -1, 0, 0}, dk[6] = {0, 0, 0, 0, 1, -1};
        const double cell_volume = f.step * f.step * f.step;
        for (std::size_t start = 0; start < total; ++start) {
            if (!clear[start] || f.label[start] >= 0) continue;
            const int comp = static_cast<int>(f.size.size());
            f.size.push_back(0.0);
            f.label[start] = comp;
            stack.assign(1, start);
            while (!stack.empty()) {
                const std::size_t c = stack.back();
                stack.pop_back();
                f.size[comp] += cell_volume;
                const int i = static_cast<int>(c % f.n[0]), j = static_cast<int>((c / f.n[0]) % f.n[1]),
                          k = static_cast<int>(c / (static_cast<std::size_t>(f.n[0]) * f.n[1]));
                for (int d = 0; d < 6; ++d) {
                    const int ni = i + di[d], nj = j + dj[d], nk = k + dk[d];
                    if (ni < 0 || nj < 0 || nk < 0 || ni >= f.n[0] || nj >= f.n[1] || nk >= f.n[2]) continue;
                    const std::size_t n = index(ni, nj, nk);
                    if (!clear[n] || f.label[n] >= 0) continue;
                    if (free_distance(center(i, j, k), Vec3(di[d], dj[d], dk[d]), f.step) < f.step) continue;
                    f.label[n] = comp;
                    stack.push_back(n);
                }
            }
        }
        for (double s : f.size) f.largest = std::max(f.largest, s);
    });
    return free_;
}

int SphereCollider::component_at(const Vec3& p) const {
    const FreeSpace& f = free_space();
    if (!is_free(p)) return -1;
    std::array<int, 3> c0{};
    for (int d = 0; d < 3; ++d) c0[d] = static_cast<int>(std::floor((p[d] - f.origin[d]) / f.step));
    // The cell holding p, or a neighbor whose center p can reach in a straight line.
    for (int dk = -1; dk <= 1; ++dk)
        for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
                const int i = c0[0] + di, j = c0[1] + dj, k = c0[2] + dk;
                if (i < 0 || j < 0 || k < 0 || i >= f.n[0] || j >= f.n[1] || k >= f.n[2]) continue;
                const int label = f.label[(static_cast<std::size_t>(k) * f.n[1] + j) * f.n[0] + i];
                if (label < 0) continue;
                const Vec3 c = f.origin + f.step * Vec3(i + 0.5, j + 0.5, k + 0.5);
                const double dist = (c - p).norm();
                if (dist == 0.0 || free_distance(p, (c - p) / dist, dist) >= dist) return label;
            }
    return -1;
}

std::pair<double, double> SphereCollider::free_volume(const Vec3& p) const {
    const int c = component_at(p);
    return {c < 0 ? 0.0 : free_.size[c], free_space().largest};
}

bool SphereCollider::can_start_at(const Vec3& p) const {
    const auto [size, largest] = free_volume(p);
    return size > 0 && size >= 0.25 * largest;
}

}  // namespace bvc3d

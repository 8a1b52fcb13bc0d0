#include "bvc3d/agent/body_collider.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

namespace {

// The part of a triangle with z_lo <= z <= z_hi (a convex polygon, possibly empty).
std::vector<Vec3> clip_to_slab(const std::array<Vec3, 3>& tri, double z_lo, double z_hi) {
    std::vector<Vec3> poly(tri.begin(), tri.end());
    auto clip = [&](double z0, double sign) {  // keep sign·(z - z0) >= 0
        std::vector<Vec3> out;
        const std::size_t n = poly.size();
        for (std::size_t i = 0; i < n; ++i) {
            const Vec3& a = poly[i];
            const Vec3& b = poly[(i + 1) % n];
            const double da = sign * (a.z() - z0), db = sign * (b.z() - z0);
            if (da >= 0) out.push_back(a);
            if ((da >= 0) != (db >= 0)) {
                Vec3 c = a + (da / (da - db)) * (b - a);
                c.z() = z0;
                out.push_back(c);
            }
        }
        poly = std::move(out);
    };
    clip(z_lo, 1.0);
    if (!poly.empty()) clip(z_hi, -1.0);
    return poly;
}

// Earliest t in [0, max_t] at which the moving point p + t·u comes within distance R of segment
// ab; max_t if never. If it is already within R, 0 when moving closer, max_t when moving away.
double contact_time(const Vec2& p, const Vec2& u, double R, const Segment2& s, double max_t) {
    const Vec2 ab = s.b - s.a;
    const double len2 = ab.squaredNorm();
    // Closest point now, to tell "already touching" apart.
    const double lam0 = len2 > 0 ? std::clamp((p - s.a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    const Vec2 d0 = p - (s.a + lam0 * ab);
    if (d0.squaredNorm() < R * R) return d0.dot(u) < 0 ? 0.0 : max_t;

    double best = max_t;
    // The flat side of the capsule facing p.
    if (len2 > 0) {
        const double len = std::sqrt(len2);
        Vec2 n(-ab.y() / len, ab.x() / len);
        double s0 = n.dot(p - s.a);
        if (s0 < 0) {
            n = -n;
            s0 = -s0;
        }
        const double approach = -n.dot(u);
        if (approach > 0 && s0 >= R) {
            const double t = (s0 - R) / approach;
            const double lam = (p + t * u - s.a).dot(ab) / len2;
            if (t <= best && lam >= 0.0 && lam <= 1.0) best = t;
        }
    }
    // The round ends: |p + t u - c|^2 = R^2, entering root.
    for (const Vec2& c : {s.a, s.b}) {
        const Vec2 w = p - c;
        const double b = w.dot(u);
        const double disc = b * b - (w.squaredNorm() - R * R);
        if (disc < 0) continue;
        const double t = -b - std::sqrt(disc);
        if (t >= 0 && t < best) best = t;
    }
    return best;
}

// Distance from p to the obstacle s (its segment grown by its radius; negative inside).
double point_segment_distance(const Vec2& p, const Segment2& s) {
    const Vec2 ab = s.b - s.a;
    const double len2 = ab.squaredNorm();
    const double lam = len2 > 0 ? std::clamp((p - s.a).dot(ab) / len2, 0.0, 1.0) : 0.0;
    return (p - (s.a + lam * ab)).norm() - s.radius;
}

// Distance between segments pq and s (s grown by its radius).
double segment_segment_distance(const Vec2& p, const Vec2& q, const Segment2& s) {
    const auto cross = [](const Vec2& u, const Vec2& v) { return u.x() * v.y() - u.y() * v.x(); };
    const Vec2 r = q - p, e = s.b - s.a;
    const double denom = cross(r, e);
    if (denom != 0.0) {  // proper crossing
        const double t = cross(s.a - p, e) / denom, u = cross(s.a - p, r) / denom;
        if (t >= 0 && t <= 1 && u >= 0 && u <= 1) return -s.radius;
    }
    const Segment2 pq{p, q, 0.0};
    return std::min({point_segment_distance(p, s), point_segment_distance(q, s),
                     point_segment_distance(s.a, pq) - s.radius, point_segment_distance(s.b, pq) - s.radius});
}

}  // namespace

BodyCollider::BodyCollider(const WorldDescription& world, double radius, double height)
    : radius_(radius), walkable_(world.walkable) {
    if (!(radius > 0) || !(height > 0)) throw InputError("robot radius and height must be positive");
    if (walkable_.points.size() < 3 || walkable_.area() <= 0)
        throw InputError("world '" + world.name + "': the walkable region needs at least 3 points and a positive area");

    // Triangles touching the slab just above the floor up to the body's top. The tiny lower bound
    // keeps floor triangles (z = 0) out while walls standing on the floor count from their base; a
    // world may let the body pass over low things (its step height).
    const double z_lo = std::max(1e-9, world.step_height);
    if (!(z_lo < height))
        throw InputError("world '" + world.name + "': its step height (" + std::to_string(world.step_height) +
                         " m) must be below the robot's height");
    for (std::size_t t = 0; t < world.mesh.size(); ++t) {
        const auto poly = clip_to_slab(world.mesh.corners(t), z_lo, height);
        for (std::size_t i = 0; i < poly.size(); ++i) {
            const Vec3& a = poly[i];
            const Vec3& b = poly[(i + 1) % poly.size()];
            add_segment(a.head<2>(), b.head<2>());
        }
    }
    for (const auto& set : world.spheres) add_spheres(set, z_lo, height);
    const auto& w = walkable_.points;
    for (std::size_t i = 0; i < w.size(); ++i) add_segment(w[i], w[(i + 1) % w.size()]);
    for (const auto& e : world.drop_edges) add_segment(e[0], e[1]);

    // Grid cells about the size of the body: a move query touches a handful of them.
    for (const auto& s : segments_) {
        bounds_.extend(s.a - Vec2::Constant(s.radius));
        bounds_.extend(s.b + Vec2::Constant(s.radius));
    }
    cell_ = std::max(4.0 * radius_, 1e-3);
    nx_ = std::max(1, static_cast<int>(std::ceil(bounds_.sizes().x() / cell_)));
    ny_ = std::max(1, static_cast<int>(std::ceil(bounds_.sizes().y() / cell_)));
    while (static_cast<double>(nx_) * ny_ > 4e6) {  // keep the grid's memory bounded
        cell_ *= 2;
        nx_ = std::max(1, static_cast<int>(std::ceil(bounds_.sizes().x() / cell_)));
        ny_ = std::max(1, static_cast<int>(std::ceil(bounds_.sizes().y() / cell_)));
    }
    grid_.assign(static_cast<std::size_t>(nx_) * ny_, {});
    for (std::size_t i = 0; i < segments_.size(); ++i) {
        Eigen::AlignedBox2d box;
        box.extend(segments_[i].a - Vec2::Constant(segments_[i].radius));
        box.extend(segments_[i].b + Vec2::Constant(segments_[i].radius));
        const int x0 = std::clamp(static_cast<int>((box.min().x() - bounds_.min().x()) / cell_), 0, nx_ - 1);
        const int x1 = std::clamp(static_cast<int>((box.max().x() - bounds_.min().x()) / cell_), 0, nx_ - 1);
        const int y0 = std::clamp(static_cast<int>((box.min().y() - bounds_.min().y()) / cell_), 0, ny_ - 1);
        const int y1 = std::clamp(static_cast<int>((box.max().y() - bounds_.min().y()) / cell_), 0, ny_ - 1);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) grid_[static_cast<std::size_t>(y) * nx_ + x].push_back(static_cast<int>(i));
    }
    stamp_.assign(segments_.size(), 0);
}

void BodyCollider::add_spheres(const SphereSet& set, double z_lo, double z_hi) {
    const double rho = set.radius;
    for (const Vec3& c : set.centers) {
        const double dz = c.z() < z_lo ? z_lo - c.z() : c.z() > z_hi ? c.z() - z_hi : 0.0;
        if (dz >= rho) continue;  // the sphere misses the slab
        const Vec2 xy = c.head<2>();
        segments_.push_back({xy, xy, std::sqrt(rho * rho - dz * dz)});
    }
}

void BodyCollider::add_segment(const Vec2& a, const Vec2& b) {
    if ((a - b).squaredNorm() == 0.0) {
        segments_.push_back({a, b});  // a point still blocks the body
        return;
    }
    // Projected edges of adjacent triangles repeat: keep one copy of exact repeats.
    for (std::size_t i = segments_.size(); i-- > 0 && i + 64 > segments_.size();) {
        const auto& s = segments_[i];
        if ((s.a == a && s.b == b) || (s.a == b && s.b == a)) return;
    }
    segments_.push_back({a, b});
}

template <class F>
void BodyCollider::for_segments_near(const Eigen::AlignedBox2d& box, F&& f) const {
    if (grid_.empty()) return;
    if (++epoch_ == 0) {
        std::fill(stamp_.begin(), stamp_.end(), 0u);
        epoch_ = 1;
    }
    const int x0 = std::clamp(static_cast<int>(std::floor((box.min().x() - bounds_.min().x()) / cell_)), 0, nx_ - 1);
    const int x1 = std::clamp(static_cast<int>(std::floor((box.max().x() - bounds_.min().x()) / cell_)), 0, nx_ - 1);
    const int y0 = std::clamp(static_cast<int>(std::floor((box.min().y() - bounds_.min().y()) / cell_)), 0, ny_ - 1);
    const int y1 = std::clamp(static_cast<int>(std::floor((box.max().y() - bounds_.min().y()) / cell_)), 0, ny_ - 1);
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x)
            for (int i : grid_[static_cast<std::size_t>(y) * nx_ + x])
                if (stamp_[i] != epoch_) {
                    stamp_[i] = epoch_;
                    f(i);
                }
}

double BodyCollider::free_distance(const Vec2& p, const Vec2& u, double max_dist) const {
    Eigen::AlignedBox2d box;
    box.extend(p);
    box.extend(p + max_dist * u);
    box.min().array() -= radius_;
    box.max().array() += radius_;
    double t = max_dist;
    for_segments_near(
        box, [&](int i) { t = std::min(t, contact_time(p, u, radius_ + segments_[i].radius, segments_[i], t)); });
    return t;
}

const BodyCollider::FreeSpace& BodyCollider::free_space() const {
    std::call_once(free_once_, [this] {
        FreeSpace& f = free_;
        f.box = walkable_.bounds();
        f.step = std::clamp(radius_ / 4, 0.02, 0.1);
        // A coarser grid for huge floors keeps the memory and time bounded (4 million cells).
        while (f.box.sizes().x() / f.step * (f.box.sizes().y() / f.step) > 4e6) f.step *= 2;
        f.nx = std::max(1, static_cast<int>(std::ceil(f.box.sizes().x() / f.step)));
        f.ny = std::max(1, static_cast<int>(std::ceil(f.box.sizes().y() / f.step)));
        const auto center = [&](int i, int j) {
            return Vec2(f.box.min().x() + (i + 0.5) * f.step, f.box.min().y() + (j + 0.5) * f.step);
        };
        std::vector<char> clear(static_cast<std::size_t>(f.nx) * f.ny);
        for (int j = 0; j < f.ny; ++j)
            for (int i = 0; i < f.nx; ++i) clear[static_cast<std::size_t>(j) * f.nx + i] = is_free(center(i, j));
        // Flood fill over moves between neighboring centers that the body can make.
        f.label.assign(clear.size(), -1);
        std::vector<int> stack;
        const int di[4] = {1, -1, 0, 0}, dj[4] = {0, 0, 1, -1};
        for (std::size_t start = 0; start < clear.size(); ++start) {
            if (!clear[start] || f.label[start] >= 0) continue;
            const int comp = static_cast<int>(f.area.size());
            f.area.push_back(0.0);
            f.label[start] = comp;
            stack.assign(1, static_cast<int>(start));
            while (!stack.empty()) {
                const int c = stack.back();
                stack.pop_back();
                f.area[comp] += f.step * f.step;
                const int i = c % f.nx, j = c / f.nx;
                for (int d = 0; d < 4; ++d) {
                    const int ni = i + di[d], nj = j + dj[d];
                    if (ni < 0 || nj < 0 || ni >= f.nx || nj >= f.ny) continue;
                    const int n = nj * f.nx + ni;
                    if (!clear[n] || f.label[n] >= 0) continue;
                    if (free_distance(center(i, j), Vec2(di[d], dj[d]), f.step) < f.step) continue;
                    f.label[n] = comp;
                    stack.push_back(n);
                }
            }
        }
        for (double a : f.area) f.largest = std::max(f.largest, a);
    });
    return free_;
}

int BodyCollider::component_at(const Vec2& p) const {
    const FreeSpace& f = free_space();
    if (!is_free(p)) return -1;
    const int i0 = static_cast<int>(std::floor((p.x() - f.box.min().x()) / f.step));
    const int j0 = static_cast<int>(std::floor((p.y() - f.box.min().y()) / f.step));
    // The cell holding p, or a neighbor whose center p can reach in a straight line.
    for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
            const int i = i0 + di, j = j0 + dj;
            if (i < 0 || j < 0 || i >= f.nx || j >= f.ny) continue;
            const int label = f.label[static_cast<std::size_t>(j) * f.nx + i];
            if (label < 0) continue;
            const Vec2 c(f.box.min().x() + (i + 0.5) * f.step, f.box.min().y() + (j + 0.5) * f.step);
            const double dist = (c - p).norm();
            if (dist == 0.0 || free_distance(p, (c - p) / dist, dist) >= dist) return label;
        }
    return -1;
}

std::pair<double, double> BodyCollider::free_area(const Vec2& p) const {
    const int c = component_at(p);
    return {c < 0 ? 0.0 : free_.area[c], free_space().largest};
}

bool BodyCollider::can_start_in(const Polygon2& region) const {
    const FreeSpace& f = free_space();
    for (int j = 0; j < f.ny; ++j)
        for (int i = 0; i < f.nx; ++i) {
            const int label = f.label[static_cast<std::size_t>(j) * f.nx + i];
            const Vec2 c(f.box.min().x() + (i + 0.5) * f.step, f.box.min().y() + (j + 0.5) * f.step);
            if (label >= 0 && f.area[label] >= 0.25 * f.largest && region.contains(c)) return true;
        }
    return false;
}

bool BodyCollider::can_start_at(const Vec2& p) const {
    const auto [area, largest] = free_area(p);
    return area > 0 && area >= 0.25 * largest;
}

double BodyCollider::clearance(const Vec2& a, const Vec2& b) const {
    double best = std::numeric_limits<double>::infinity();
    for (double reach = cell_;; reach *= 2) {
        Eigen::AlignedBox2d box;
        box.extend(a - Vec2::Constant(reach));
        box.extend(b + Vec2::Constant(reach));
        box.extend(a + Vec2::Constant(reach));
        box.extend(b - Vec2::Constant(reach));
        for_segments_near(box, [&](int i) { best = std::min(best, segment_segment_distance(a, b, segments_[i])); });
        if (best <= reach || reach > 2 * (bounds_.sizes().norm() + (a - bounds_.center()).norm())) break;
    }
    return best - radius_;
}

double BodyCollider::clearance(const Vec2& p) const {
    // Grow the search box until it holds a segment, then check everything that could be closer.
    double best = std::numeric_limits<double>::infinity();
    for (double reach = cell_;; reach *= 2) {
        Eigen::AlignedBox2d box(p - Vec2::Constant(reach), p + Vec2::Constant(reach));
        for_segments_near(box, [&](int i) { best = std::min(best, point_segment_distance(p, segments_[i])); });
        if (best <= reach || reach > 2 * (bounds_.sizes().norm() + (p - bounds_.center()).norm())) break;
    }
    return best - radius_;
}

}  // namespace bvc3d

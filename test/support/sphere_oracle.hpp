#pragma once
// Distances for checking the flying agent's collision (docs/flying.md), written independently of the
// library's SphereCollider: the point is projected onto the triangle's plane and tested inside by
// solving for its barycentric coordinates; outside, the nearest of the three edges (each a clamped
// projection) wins. No code is shared with src/bvc3d/agent/sphere_collider.cpp.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace bvc3d::oracle {

using P3 = std::array<double, 3>;

inline P3 sub(const P3& a, const P3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot(const P3& a, const P3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline P3 cross(const P3& a, const P3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

inline double point_segment(const P3& p, const P3& a, const P3& b) {
    const P3 ab = sub(b, a), ap = sub(p, a);
    const double len2 = dot(ab, ab);
    const double s = len2 > 0 ? std::clamp(dot(ap, ab) / len2, 0.0, 1.0) : 0.0;
    const P3 d = {ap[0] - s * ab[0], ap[1] - s * ab[1], ap[2] - s * ab[2]};
    return std::sqrt(dot(d, d));
}

// Exact distance from p to the (closed) triangle abc.
inline double point_triangle(const P3& p, const P3& a, const P3& b, const P3& c) {
    const P3 u = sub(b, a), v = sub(c, a), w = sub(p, a);
    const P3 n = cross(u, v);
    const double nn = dot(n, n);
    if (nn > 0) {
        // p - a = s·u + t·v + h·n: solve the 2x2 normal equations for s, t.
        const double uu = dot(u, u), uv = dot(u, v), vv = dot(v, v), wu = dot(w, u), wv = dot(w, v);
        const double det = uu * vv - uv * uv;
        const double s = (vv * wu - uv * wv) / det, t = (uu * wv - uv * wu) / det;
        if (s >= 0 && t >= 0 && s + t <= 1) return std::abs(dot(w, n)) / std::sqrt(nn);
    }
    return std::min({point_segment(p, a, b), point_segment(p, b, c), point_segment(p, c, a)});
}

struct Triangle {
    P3 a, b, c;
};

inline double nearest(const P3& p, const std::vector<Triangle>& tris) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : tris) best = std::min(best, point_triangle(p, t.a, t.b, t.c));
    return best;
}

}  // namespace bvc3d::oracle

#include "bvc3d/world/mesh.hpp"

#include <cmath>

namespace bvc3d {

void TriangleMesh::add_triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
    const auto base = static_cast<std::uint32_t>(vertices.size());
    vertices.push_back(a);
    vertices.push_back(b);
    vertices.push_back(c);
    triangles.push_back({base, base + 1, base + 2});
}

void TriangleMesh::add_quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    const auto base = static_cast<std::uint32_t>(vertices.size());
    vertices.insert(vertices.end(), {a, b, c, d});
    triangles.push_back({base, base + 1, base + 2});
    triangles.push_back({base, base + 2, base + 3});
}

void TriangleMesh::append(const TriangleMesh& other, const Eigen::Isometry3d& pose) {
    const auto base = static_cast<std::uint32_t>(vertices.size());
    for (const auto& v : other.vertices) vertices.push_back(pose * v);
    for (const auto& t : other.triangles) triangles.push_back({base + t[0], base + t[1], base + t[2]});
}

TriangleMesh hexahedron_mesh(const std::array<Vec3, 4>& b, const std::array<Vec3, 4>& t) {
    TriangleMesh m;
    m.add_quad(b[0], b[3], b[2], b[1]);  // bottom
    m.add_quad(t[0], t[1], t[2], t[3]);  // top
    for (int i = 0; i < 4; ++i) {
        const int j = (i + 1) % 4;
        m.add_quad(b[i], b[j], t[j], t[i]);
    }
    return m;
}

TriangleMesh box_mesh(const Vec3& size) {
    const Vec3 h = 0.5 * size;
    const std::array<Vec3, 4> bottom{Vec3(-h.x(), -h.y(), -h.z()), Vec3(h.x(), -h.y(), -h.z()),
                                     Vec3(h.x(), h.y(), -h.z()), Vec3(-h.x(), h.y(), -h.z())};
    std::array<Vec3, 4> top = bottom;
    for (auto& v : top) v.z() = h.z();
    return hexahedron_mesh(bottom, top);
}

TriangleMesh tilted_wall_mesh(const TiltedWall& w) {
    const Vec2 along(std::cos(w.yaw), std::sin(w.yaw));
    const Vec2 left(-along.y(), along.x());
    const double half_len = 0.5 * w.length;
    const double half_thick = 0.5 * w.thickness / std::cos(w.tilt);
    const Vec2 shift = w.height * std::tan(w.tilt) * left;
    std::array<Vec3, 4> bottom, top;
    const double s[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int i = 0; i < 4; ++i) {
        const Vec2 p = w.center + s[i][0] * half_len * along + s[i][1] * half_thick * left;
        bottom[i] = Vec3(p.x(), p.y(), 0.0);
        top[i] = Vec3(p.x() + shift.x(), p.y() + shift.y(), w.height);
    }
    return hexahedron_mesh(bottom, top);
}

double triangle_double_area(const Vec3& a, const Vec3& b, const Vec3& c) { return (b - a).cross(c - a).norm(); }

bool Polygon2::contains(const Vec2& p) const {
    bool inside = false;
    const std::size_t n = points.size();
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
        const Vec2& a = points[i];
        const Vec2& b = points[j];
        if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
            inside = !inside;
    }
    return inside;
}

double Polygon2::area() const {
    double s = 0.0;
    const std::size_t n = points.size();
    for (std::size_t i = 0, j = n - 1; i < n; j = i++)
        s += points[j].x() * points[i].y() - points[i].x() * points[j].y();
    return 0.5 * std::abs(s);
}

Eigen::AlignedBox2d Polygon2::bounds() const {
    Eigen::AlignedBox2d box;
    for (const auto& p : points) box.extend(p);
    return box;
}

Polygon2 Polygon2::rectangle(double xmin, double ymin, double xmax, double ymax) {
    return Polygon2{{Vec2(xmin, ymin), Vec2(xmax, ymin), Vec2(xmax, ymax), Vec2(xmin, ymax)}};
}

}  // namespace bvc3d

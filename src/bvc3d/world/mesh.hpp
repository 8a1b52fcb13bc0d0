#pragma once
// Triangle geometry: what worlds are made of. Plain data, double precision.
#include <array>
#include <cstdint>
#include <vector>

#include "bvc3d/core/geometry.hpp"

namespace bvc3d {

// World coordinates lie within ±max_coordinate meters: anything beyond is a unit or frame mistake
// (and far beyond it ray casting loses all precision).
inline constexpr double max_coordinate = 1e6;

struct TriangleMesh {
    std::vector<Vec3> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;

    std::size_t size() const { return triangles.size(); }
    bool empty() const { return triangles.empty(); }
    void add_triangle(const Vec3& a, const Vec3& b, const Vec3& c);
    void add_quad(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d);  // a-b-c-d in order
    // Append another mesh, its vertices mapped through `pose`.
    void append(const TriangleMesh& other, const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity());
    std::array<Vec3, 3> corners(std::size_t t) const {
        const auto& i = triangles[t];
        return {vertices[i[0]], vertices[i[1]], vertices[i[2]]};
    }
};

// A convex hexahedron given by its 8 corners: bottom face b0..b3, top face t0..t3 (same order).
TriangleMesh hexahedron_mesh(const std::array<Vec3, 4>& bottom, const std::array<Vec3, 4>& top);

// Axis-aligned box of the given full size, centered on the origin.
TriangleMesh box_mesh(const Vec3& size);

// A straight wall standing on z = 0 whose horizontal cross-section slides sideways with height:
// at height z it is the rectangle of the given length and thickness centered on
// center + z·tan(tilt)·left_normal, with left_normal = (-sin yaw, cos yaw). The footprint stays put
// and the horizontal thickness is thickness / cos(tilt) (docs/model-reference.md#the-cross-arena), so the wall's true
// thickness measured perpendicular to its faces is `thickness`.
struct TiltedWall {
    Vec2 center{0.0, 0.0};
    double length = 7.0;
    double thickness = 0.3;
    double height = 2.5;
    double yaw = 0.0;   // radians: direction of the wall's long axis from +x
    double tilt = 0.0;  // radians, positive leans toward the left normal
};
TriangleMesh tilted_wall_mesh(const TiltedWall& wall);

// Twice the area of a triangle; zero for degenerate ones.
double triangle_double_area(const Vec3& a, const Vec3& b, const Vec3& c);

// A simple polygon in the floor plane (counter-clockwise or clockwise).
struct Polygon2 {
    std::vector<Vec2> points;
    bool contains(const Vec2& p) const;
    double area() const;  // absolute
    Eigen::AlignedBox2d bounds() const;
    static Polygon2 rectangle(double xmin, double ymin, double xmax, double ymax);
};

}  // namespace bvc3d

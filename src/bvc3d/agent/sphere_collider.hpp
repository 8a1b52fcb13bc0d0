#pragma once
// Exact collision of a flying agent's body (a sphere) with the world and its flight volume
// (docs/flying.md#the-flying-agent).
//
// The sphere of radius R touches a triangle iff its center comes within R of it. A move from p along
// u is cut at the earliest such contact, found exactly over the triangle's offset surface: the two
// faces shifted by R along the normal, a cylinder of radius R around each edge and a ball around
// each vertex (the first entry into their union is the first entry into one of them). So no speed
// tunnels through a wall. The flight volume's sides (vertical walls over its region's edges) and its
// floor and ceiling are triangles too, so the body never leaves it.
// Takes: a WorldDescription with a flight volume, a radius. Gives: free distances, clearances, and
// the connected free space (for starts and coverage).
#include <array>
#include <mutex>
#include <utility>
#include <vector>

#include "bvc3d/world/world.hpp"

namespace bvc3d {

class SphereCollider {
public:
    // InputError if the world has no flight volume or the volume cannot hold the body.
    SphereCollider(const WorldDescription& world, double radius);

    double radius() const { return radius_; }
    const FlightVolume& volume() const { return volume_; }
    // The box the body's center can be in (the volume shrunk by the radius).
    const Eigen::AlignedBox3d& center_box() const { return center_box_; }

    // How far the center can move from p along the unit vector u, up to max_dist, before the body
    // touches geometry or the volume's boundary. 0 if it already touches and u points into the contact.
    double free_distance(const Vec3& p, const Vec3& u, double max_dist) const;

    // Distance from the center p to the nearest triangle of the world or of the volume's boundary,
    // minus the radius (< 0: overlap).
    double clearance(const Vec3& p) const;
    // Inside the volume (center in the region and within [z_min + R, z_max - R]) and clear of geometry.
    bool is_free(const Vec3& p) const;

    // A place a flight may start: free, and connected by collision-free motion to a free volume at
    // least a quarter the size of the largest one (the inside of a solid pillar is a separate, smaller
    // one). Built on first use on a grid of center positions `free_space_step()` apart.
    bool can_start_at(const Vec3& p) const;
    // Volume (m³ of center positions) of the free region p belongs to (0 if none) and of the largest.
    std::pair<double, double> free_volume(const Vec3& p) const;
    double free_space_step() const;

private:
    struct Triangle {
        Vec3 a, b, c;
        Vec3 n;  // unit normal
    };
    void add_triangle(const Vec3& a, const Vec3& b, const Vec3& c);
    template <class F>
    void for_triangles_near(const Eigen::AlignedBox3d& box, F&& f) const;
    bool touches_any(const Vec3& p) const;  // some triangle closer than R

    double radius_;
    FlightVolume volume_;
    Eigen::AlignedBox3d center_box_;
    std::vector<Triangle> triangles_;
    // Uniform grid over the triangles' bounds: cell -> triangle indices.
    Eigen::AlignedBox3d bounds_;
    double cell_ = 1.0;
    std::array<int, 3> n_{1, 1, 1};
    std::vector<std::vector<int>> grid_;
    mutable std::vector<unsigned> stamp_;
    mutable unsigned epoch_ = 0;

    // Connected free regions on a grid of center positions, built on first use.
    struct FreeSpace {
        Vec3 origin = Vec3::Zero();
        double step = 0;
        std::array<int, 3> n{0, 0, 0};
        std::vector<int> label;    // per cell: component, or -1 where the body does not fit
        std::vector<double> size;  // per component, m³
        double largest = 0;
    };
    const FreeSpace& free_space() const;
    int component_at(const Vec3& p) const;
    mutable std::once_flag free_once_;
    mutable FreeSpace free_;
};

// The point of triangle abc nearest to p (Ericson, Real-Time Collision Detection §5.1.5).
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace bvc3d

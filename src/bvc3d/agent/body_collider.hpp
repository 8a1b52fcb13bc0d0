#pragma once
// Exact collision of the robot's body (a vertical cylinder standing on z = 0) with the world.
//
// The cylinder, radius R and height H, touches a triangle iff its disc touches the floor-plane
// projection of the triangle's part with 0 < z <= H. Those projections are convex polygons, so
// the 3-D test reduces to a disc against 2-D segments (their edges), exactly. Triangles lying at
// z <= 0 (or below the world's step height) are floor and never collide. The walkable region's
// boundary and the world's drop edges (where its floor ends) also count as walls.
// A sphere (a point of a point cloud, center c, radius ρ) cut by the same slab is a ball whose
// floor-plane projection is the disc of radius √(ρ² − dz²) around c's (x, y), dz being the distance
// from c.z to the slab (0 inside it): the body touches it iff its disc touches that disc, so a
// sphere is a round obstacle of that radius, exactly too.
#include <mutex>
#include <vector>

#include "bvc3d/world/world.hpp"

namespace bvc3d {

// A segment, or a disc when a == b; `radius` grows it into a capsule (a sphere's cross-section).
struct Segment2 {
    Vec2 a, b;
    double radius = 0.0;
};

class BodyCollider {
public:
    BodyCollider(const WorldDescription& world, double radius, double height);

    double radius() const { return radius_; }
    const Polygon2& walkable() const { return walkable_; }
    const std::vector<Segment2>& segments() const { return segments_; }

    // How far the body can move from center p along the unit direction u, up to max_dist, before
    // it touches geometry. 0 if it already touches and u points into the contact.
    double free_distance(const Vec2& p, const Vec2& u, double max_dist) const;

    // Distance from the center p to the nearest obstacle (segment or disc), minus the body's radius
    // (< 0: overlap).
    double clearance(const Vec2& p) const;
    // The same for every center on the segment ab (its nearest approach): a body driven from a to b
    // stays clear of geometry iff this is >= 0.
    double clearance(const Vec2& a, const Vec2& b) const;

    // Inside the walkable region and not touching any wall. (A center deep inside a solid obstacle is
    // far from its walls too: see can_start_at.)
    bool is_free(const Vec2& p) const { return walkable_.contains(p) && clearance(p) >= 0.0; }

    // A place a walk may start: free, and connected by collision-free motion to a free area at least
    // a quarter the size of the largest one. The inside of a solid obstacle, or a closed-off pocket,
    // is a separate, smaller area. (Orientation-free: meshes need not have consistent normals.)
    bool can_start_at(const Vec2& p) const;
    // Area of the free region p belongs to (0 if none) and of the largest one, m².
    std::pair<double, double> free_area(const Vec2& p) const;
    // Whether some place inside `region` is one a walk may start from (on the free-space grid).
    bool can_start_in(const Polygon2& region) const;
    // Distance from p to the nearest geometry or walkable boundary: the largest radius that fits at p.
    double room(const Vec2& p) const { return clearance(p) + radius_; }

private:
    void add_segment(const Vec2& a, const Vec2& b);
    void add_spheres(const SphereSet& set, double z_lo, double z_hi);
    template <class F>
    void for_segments_near(const Eigen::AlignedBox2d& box, F&& f) const;

    double radius_;
    Polygon2 walkable_;
    std::vector<Segment2> segments_;
    // Uniform grid over the segments' bounds: cell -> segment indices.
    Eigen::AlignedBox2d bounds_;
    double cell_ = 1.0;
    int nx_ = 1, ny_ = 1;
    std::vector<std::vector<int>> grid_;
    mutable std::vector<unsigned> stamp_;
    mutable unsigned epoch_ = 0;

    // Connected free areas on a grid of body-center positions, built on first use.
    struct FreeSpace {
        Eigen::AlignedBox2d box;
        double step = 0;
        int nx = 0, ny = 0;
        std::vector<int> label;    // per cell: component, or -1 where the body does not fit
        std::vector<double> area;  // per component, m²
        double largest = 0;
    };
    const FreeSpace& free_space() const;
    int component_at(const Vec2& p) const;  // -1 if p cannot reach a free cell center next to it
    mutable std::once_flag free_once_;
    mutable FreeSpace free_;
};

}  // namespace bvc3d

#pragma once
// Ray queries against a triangle mesh and sets of spheres (points of a point cloud with a radius),
// through Embree 3 (spheres as its point geometry, RTC_GEOMETRY_TYPE_SPHERE_POINT).
// Embree finds the triangle or sphere a ray hits (in float); the distance is then recomputed in
// double against that triangle's plane or that sphere, so ranges are exact to ~1e-12 m rather than
// float's ~1e-6 m. Embree runs its AVX2 kernels at most, so that which triangle a grazing ray hits does
// not change between machines.
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "bvc3d/world/mesh.hpp"
#include "bvc3d/world/world.hpp"

namespace bvc3d {

class RayCaster {
public:
    // Throws InputError when there is no geometry at all, or a sphere radius is not positive.
    explicit RayCaster(const TriangleMesh& mesh, const std::vector<SphereSet>& spheres = {});
    ~RayCaster();
    RayCaster(const RayCaster&) = delete;
    RayCaster& operator=(const RayCaster&) = delete;

    static constexpr double no_hit = std::numeric_limits<double>::infinity();

    // Distance along the unit direction `dir` to the first surface within max_range, or no_hit.
    double cast(const Vec3& origin, const Vec3& dir, double max_range) const;

    // Same for many unit directions from one origin (uses Embree ray packets).
    void cast(const Vec3& origin, std::span<const Vec3> dirs, double max_range, std::span<double> ranges) const;

private:
    // What every ray of one cast() shares.
    struct Call {
        const Vec3& origin;
        double max_range;
    };
    template <int N, class RayHitN, class Intersect>
    void cast_packets(Intersect intersect, const Call& call, std::span<const Vec3> dirs,
                      std::span<double> ranges) const;
    template <int N, class RayHitN>
    void refine(const RayHitN& rh, const Call& call, std::span<const Vec3> dirs, std::span<double> ranges) const;
    double refine_other(unsigned geom, unsigned prim, const Call& call, const Vec3& dir, float t_float) const;
    double refine_sphere(const Vec3& center, double radius, const Vec3& origin, const Vec3& dir, float t_float) const;

    struct Impl;
    std::unique_ptr<Impl> impl_;  // the Embree device and scene
    // Per triangle, in double precision: its plane (unnormalized normal, a corner) and the |n·d|
    // below which a ray grazes it; then one more, read (and discarded) for rays that hit no triangle.
    struct Plane {
        Vec3 normal;
        double grazing;
    };
    std::vector<Plane> planes_;
    std::vector<Vec3> corners_;  // a corner of each plane's triangle
    // Embree geometry IDs: the triangles (if any) first, then one per sphere set, in order.
    unsigned first_sphere_geom_ = 0;
    std::vector<SphereSet> spheres_;  // its own copy: a caster is shared by copies of a World
};

}  // namespace bvc3d

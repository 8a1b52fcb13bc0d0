#include "bvc3d/world/ray_caster.hpp"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "bvc3d/core/error.hpp"

namespace bvc3d {

struct RayCaster::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    int packet = 4;  // widest ray packet the CPU runs natively: 4, 8 or 16
    ~Impl() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

namespace {

void check_device(RTCDevice device, const char* what) {
    const RTCError e = rtcGetDeviceError(device);
    if (e != RTC_ERROR_NONE)
        throw std::runtime_error(std::string("Embree error ") + std::to_string(static_cast<int>(e)) + " in " + what);
}

// Lane k of a ray packet points along dir (in float).
template <class RayHitN>
void set_direction(RayHitN& rh, int k, const Vec3& dir) {
    rh.ray.dir_x[k] = static_cast<float>(dir.x());
    rh.ray.dir_y[k] = static_cast<float>(dir.y());
    rh.ray.dir_z[k] = static_cast<float>(dir.z());
}

}  // namespace

RayCaster::RayCaster(const TriangleMesh& mesh, const std::vector<SphereSet>& spheres)
    : impl_(std::make_unique<Impl>()), spheres_(spheres) {
    std::size_t n_spheres = 0;
    for (const auto& set : spheres) {
        if (!(set.radius > 0) || !std::isfinite(set.radius))
            throw InputError("world: a point cloud's sphere radius must be a positive number");
        n_spheres += set.centers.size();
    }
    if (mesh.empty() && n_spheres == 0) throw InputError("world has no geometry (no triangles or points)");
    // Embree's kernels capped at AVX2, for the same bits on every machine: its SSE2 kernels (here) and AVX-512 ones (on
    // the machine of the regression digests) moved the final weights of the 30° arena's 3-D trials; SSE4.2, AVX and
    // AVX2 agree.
    impl_->device = rtcNewDevice("verbose=0,max_isa=avx2");
    if (!impl_->device) throw std::runtime_error("could not create an Embree device");
    impl_->scene = rtcNewScene(impl_->device);
    // Robust traversal: rays through shared edges of adjacent triangles never slip through.
    rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);

    unsigned next_geom = 0;
    if (!mesh.empty()) {
        RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), mesh.vertices.size()));
        for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
            for (int k = 0; k < 3; ++k) vb[3 * i + k] = static_cast<float>(mesh.vertices[i][k]);
        auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                  3 * sizeof(unsigned), mesh.triangles.size()));
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
            for (int k = 0; k < 3; ++k) ib[3 * t + k] = mesh.triangles[t][k];
        rtcCommitGeometry(geom);
        rtcAttachGeometryByID(impl_->scene, geom, next_geom++);
        rtcReleaseGeometry(geom);
    }
    first_sphere_geom_ = next_geom;
    for (const auto& set : spheres) {
        // One geometry per set, even an empty one, so that geometry ID - first_sphere_geom_ is the set.
        RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4,
                                                               4 * sizeof(float), set.centers.size()));
        for (std::size_t i = 0; i < set.centers.size(); ++i) {
            for (int k = 0; k < 3; ++k) vb[4 * i + k] = static_cast<float>(set.centers[i][k]);
            vb[4 * i + 3] = static_cast<float>(set.radius);
        }
        rtcCommitGeometry(geom);
        rtcAttachGeometryByID(impl_->scene, geom, next_geom++);
        rtcReleaseGeometry(geom);
    }
    rtcCommitScene(impl_->scene);
    check_device(impl_->device, "scene build");
    if (rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED)) impl_->packet = 16;
    else if (rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED)) impl_->packet = 8;

    planes_.reserve(mesh.size() + 1);
    corners_.reserve(mesh.size() + 1);
    for (std::size_t t = 0; t < mesh.size(); ++t) {
        const auto c = mesh.corners(t);
        const Vec3 normal = (c[1] - c[0]).cross(c[2] - c[0]);
        planes_.push_back({normal, 1e-9 * normal.norm()});
        corners_.push_back(c[0]);
    }
    // What refine reads for the rays that hit no triangle (and then redoes): any plane.
    planes_.push_back({Vec3::UnitZ(), 0.0});
    corners_.push_back(Vec3::Zero());
}

RayCaster::~RayCaster() = default;

// The ranges of a packet's rays, in passes over the whole packet so that the divisions of the plane
// solves and the tests after them vectorize. A ray that is not a triangle hit at a clear angle (a
// miss, a sphere, a grazing ray) goes through them on a stand-in plane with a denominator of 1,
// and is then redone on its own.
template <int N, class RayHitN>
void RayCaster::refine(const RayHitN& rh, const Call& call, std::span<const Vec3> dirs,
                       std::span<double> ranges) const {
    const std::size_t n = dirs.size();
    const Plane* planes = planes_.data();
    const unsigned first_sphere = first_sphere_geom_, none = static_cast<unsigned>(planes_.size() - 1);
    alignas(64) double num[N], den[N];
    unsigned others = 0;  // a bit per ray that is not a triangle hit at a clear angle
    for (std::size_t k = 0; k < n; ++k) {
        const unsigned geom = rh.hit.geomID[k], prim = rh.hit.primID[k];
        const bool triangle = geom < first_sphere;  // a miss's ID is the largest
        const unsigned t = triangle ? prim : none;
        const double d = planes[t].normal.dot(dirs[k]);
        // Grazing rays: the plane solve is ill-conditioned, Embree's float distance is better.
        const bool other = !triangle || !(std::abs(d) > planes[t].grazing);
        den[k] = other ? 1.0 : d;  // no division by zero for the rays redone below
        num[k] = planes[t].normal.dot(corners_[t] - call.origin);
        others |= static_cast<unsigned>(other) << k;
    }
    const double max_range = call.max_range;
    for (std::size_t k = 0; k < n; ++k) {
        const double r = std::max(0.0, num[k] / den[k]);
        ranges[k] = r > max_range ? no_hit : r;
    }
    for (std::size_t k = 0; others; ++k, others >>= 1)
        if (others & 1) ranges[k] = refine_other(rh.hit.geomID[k], rh.hit.primID[k], call, dirs[k], rh.ray.tfar[k]);
}

// A ray that missed, hit a sphere or grazed a triangle.
double RayCaster::refine_other(unsigned geom, unsigned prim, const Call& call, const Vec3& dir, float t_float) const {
    if (geom == RTC_INVALID_GEOMETRY_ID) return no_hit;
    double r = t_float;  // a grazing ray
    if (geom >= first_sphere_geom_) {
        const SphereSet& set = spheres_[geom - first_sphere_geom_];
        r = refine_sphere(set.centers[prim], set.radius, call.origin, dir, t_float);
    }
    return r > call.max_range ? no_hit : r;
}

double RayCaster::refine_sphere(const Vec3& center, double radius, const Vec3& origin, const Vec3& dir,
                                float t_float) const {
    // |origin + t·dir - center| = radius: t = b ∓ √(b² - q), b = dir·w, q = |w|² - radius², w = center - origin.
    // Embree chose the sphere in float; a ray grazing it that misses in double (by ~1e-7 of the
    // radius) takes its point of closest approach, and one that disagrees about the side takes
    // Embree's float distance, as grazing rays on triangles do.
    const Vec3 w = center - origin;
    const double b = dir.dot(w), q = w.squaredNorm() - radius * radius;
    const double disc = b * b - q;
    if (q <= 0) return b + std::sqrt(std::max(0.0, disc));  // from inside the sphere: its far side
    if (b <= 0) return t_float;
    if (disc <= 0) return b;
    return q / (b + std::sqrt(disc));  // the near root, without cancellation
}

double RayCaster::cast(const Vec3& origin, const Vec3& dir, double max_range) const {
    double r;
    cast(origin, std::span<const Vec3>(&dir, 1), max_range, std::span<double>(&r, 1));
    return r;
}

// Packets of N rays from a common origin through rtcIntersect{4,8,16}. The fields every ray of the
// call shares are written once (Embree writes instID[0] only with the context's, invalid, value);
// each packet writes its directions and resets its hit.
template <int N, class RayHitN, class Intersect>
void RayCaster::cast_packets(Intersect intersect, const Call& call, std::span<const Vec3> dirs,
                             std::span<double> ranges) const {
    const Vec3& origin = call.origin;
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;  // every ray shares the origin
    // Embree's far limit is float: widen it by a hair so the exact double test below decides.
    const float tfar = static_cast<float>(call.max_range) * (1.0f + 1e-6f);
    alignas(64) RayHitN rh;
    alignas(64) int valid[N];
    for (int k = 0; k < N; ++k) {
        valid[k] = -1;
        rh.ray.org_x[k] = static_cast<float>(origin.x());
        rh.ray.org_y[k] = static_cast<float>(origin.y());
        rh.ray.org_z[k] = static_cast<float>(origin.z());
        rh.ray.tnear[k] = 0.0f;
        rh.ray.time[k] = 0.0f;
        rh.ray.mask[k] = 0xFFFFFFFFu;
        rh.ray.id[k] = static_cast<unsigned>(k);
        rh.ray.flags[k] = 0;
        rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID[k] = 0;  // refine reads it (and drops it) for rays that hit nothing
    }
    for (std::size_t i = 0; i < dirs.size(); i += N) {
        const std::size_t n = std::min<std::size_t>(N, dirs.size() - i);
        if (n == N) {
            for (int k = 0; k < N; ++k) set_direction(rh, k, dirs[i + k]);
        } else {  // the last packet: its idle lanes repeat its first ray and are masked off
            for (int k = 0; k < N; ++k) {
                const bool used = static_cast<std::size_t>(k) < n;
                set_direction(rh, k, dirs[i + (used ? k : 0)]);
                valid[k] = used ? -1 : 0;
            }
        }
        for (int k = 0; k < N; ++k) {
            rh.ray.tfar[k] = tfar;
            rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
        }
        intersect(valid, impl_->scene, &ctx, &rh);
        refine<N>(rh, call, dirs.subspan(i, n), ranges.subspan(i, n));
    }
}

void RayCaster::cast(const Vec3& origin, std::span<const Vec3> dirs, double max_range, std::span<double> ranges) const {
    const Call call{origin, max_range};
    switch (impl_->packet) {
        case 16:
            return cast_packets<16, RTCRayHit16>(rtcIntersect16, call, dirs, ranges);
        case 8:
            return cast_packets<8, RTCRayHit8>(rtcIntersect8, call, dirs, ranges);
        default:
            return cast_packets<4, RTCRayHit4>(rtcIntersect4, call, dirs, ranges);
    }
}

}  // namespace bvc3d

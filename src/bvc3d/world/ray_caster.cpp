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
};

namespace {

void check_device(RTCDevice device, const char* what) {
    const RTCError e = rtcGetDeviceError(device);
    if (e != RTC_ERROR_NONE)
        throw std::runtime_error(std::string("Embree error ") + std::to_string(static_cast<int>(e)) + " in " + what);
}

}  // namespace

RayCaster::RayCaster(const TriangleMesh& mesh) : impl_(new Impl) {
    if (mesh.empty()) {
        delete impl_;
        throw InputError("world has no geometry (no triangles)");
    }
    impl_->device = rtcNewDevice("verbose=0");
    if (!impl_->device) {
        delete impl_;
        throw std::runtime_error("could not create an Embree device");
    }
    impl_->scene = rtcNewScene(impl_->device);
    // Robust traversal: rays through shared edges of adjacent triangles never slip through.
    rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);

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
    rtcAttachGeometry(impl_->scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(impl_->scene);
    check_device(impl_->device, "scene build");

    plane_point_.reserve(mesh.size());
    plane_normal_.reserve(mesh.size());
    for (std::size_t t = 0; t < mesh.size(); ++t) {
        const auto c = mesh.corners(t);
        plane_point_.push_back(c[0]);
        plane_normal_.push_back((c[1] - c[0]).cross(c[2] - c[0]));
    }
}

RayCaster::~RayCaster() {
    if (impl_->scene) rtcReleaseScene(impl_->scene);
    if (impl_->device) rtcReleaseDevice(impl_->device);
    delete impl_;
}

double RayCaster::refine(unsigned prim, const Vec3& origin, const Vec3& dir, float t_float) const {
    const Vec3& n = plane_normal_[prim];
    const double nd = n.dot(dir);
    // Grazing rays: the plane solve is ill-conditioned, Embree's float distance is better.
    if (std::abs(nd) <= 1e-9 * n.norm()) return t_float;
    return std::max(0.0, n.dot(plane_point_[prim] - origin) / nd);
}

double RayCaster::cast(const Vec3& origin, const Vec3& dir, double max_range) const {
    double r;
    cast(origin, std::span<const Vec3>(&dir, 1), max_range, std::span<double>(&r, 1));
    return r;
}

void RayCaster::cast(const Vec3& origin, std::span<const Vec3> dirs, double max_range,
                     std::span<double> ranges) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    // Embree's far limit is float: widen it by a hair so the exact double test below decides.
    const float tfar = static_cast<float>(max_range) * (1.0f + 1e-6f);
    for (std::size_t i = 0; i < dirs.size(); ++i) {
        RTCRayHit rh;
        rh.ray.org_x = static_cast<float>(origin.x());
        rh.ray.org_y = static_cast<float>(origin.y());
        rh.ray.org_z = static_cast<float>(origin.z());
        rh.ray.dir_x = static_cast<float>(dirs[i].x());
        rh.ray.dir_y = static_cast<float>(dirs[i].y());
        rh.ray.dir_z = static_cast<float>(dirs[i].z());
        rh.ray.tnear = 0.0f;
        rh.ray.tfar = tfar;
        rh.ray.time = 0.0f;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(impl_->scene, &ctx, &rh);
        double r = no_hit;
        if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
            r = refine(rh.hit.primID, origin, dirs[i], rh.ray.tfar);
            if (r > max_range) r = no_hit;
        }
        ranges[i] = r;
    }
}

}  // namespace bvc3d

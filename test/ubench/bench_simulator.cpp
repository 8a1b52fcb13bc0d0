// Simulator stage: scans (rays per second) and random-walk steps in the paper's 45° arena.
#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>

#include <cstring>

#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/bvc/boundary_vector_layer.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/sensor/lidar.hpp"

using namespace bvc3d;

namespace {

// Poses along a real walk, so the rays see the arena from typical places.
const std::vector<ModelStep>& poses(const World& w) {
    static const auto steps = random_walk(w, 0.2, 1);
    return steps;
}

void scan_benchmark(benchmark::State& state, LidarSpec spec) {
    const World world = World::cross({.tilt_deg = 45});
    const Lidar lidar(std::move(spec));
    const auto& walk = poses(world);
    Scan scan;
    std::size_t i = 0, rays = 0;
    for (auto _ : state) {
        const auto& s = walk[i++ % walk.size()];
        lidar.scan(world, s.pose, scan);
        benchmark::DoNotOptimize(scan.data());
        rays += lidar.spec().beam_count();
    }
    state.counters["rays/s"] = benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
}

void BM_ScanHorizontal(benchmark::State& state) { scan_benchmark(state, LidarSpec::horizontal()); }
void BM_ScanSpherical(benchmark::State& state) { scan_benchmark(state, LidarSpec::spherical()); }

// The rows a preset's model casts in a trial (its scan plan), as bvc3d casts them.
void BM_ScanPlanned(benchmark::State& state, std::string preset) {
    const ModelSpec model = model_preset(preset);
    const World world = World::cross({.tilt_deg = 45});
    const Lidar lidar(model.sensor);
    const auto plan = BoundaryVectorLayer(model.bvc).plan(model.sensor);
    const auto& walk = poses(world);
    Scan scan;
    std::size_t i = 0, rays = 0;
    for (auto _ : state) {
        lidar.scan(world, walk[i++ % walk.size()].pose, scan, {}, plan.rows);
        benchmark::DoNotOptimize(scan.data());
        rays += static_cast<std::size_t>(std::count(plan.rows.begin(), plan.rows.end(), 1)) *
                static_cast<std::size_t>(model.sensor.azimuth_count);
    }
    state.counters["rays/s"] = benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
}

// The floor of ray casting: Embree alone on the same rays (the same scene flags, packets of 16 rays
// filled in advance, one packet per 16 columns of a row), with nothing around it: no directions to
// compute, no ranges to refine in double, no returns to write.
void BM_EmbreeOnly(benchmark::State& state, std::string preset) {
    const ModelSpec model = model_preset(preset);
    const World world = World::cross({.tilt_deg = 45});
    const auto plan = BoundaryVectorLayer(model.bvc).plan(model.sensor);
    const TriangleMesh& mesh = world.mesh();
    RTCDevice device = rtcNewDevice("verbose=0");
    RTCScene scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), mesh.vertices.size()));
    for (std::size_t v = 0; v < mesh.vertices.size(); ++v)
        for (int k = 0; k < 3; ++k) vb[3 * v + k] = static_cast<float>(mesh.vertices[v][k]);
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(unsigned), mesh.triangles.size()));
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) ib[3 * t + k] = mesh.triangles[t][k];
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);

    // Every pose's packets, filled in advance.
    const auto& walk = poses(world);
    const std::size_t n_poses = std::min<std::size_t>(walk.size(), 64);
    const LidarSpec& sensor = model.sensor;
    std::vector<std::vector<RTCRayHit16>> packets(n_poses);
    std::size_t rays_per_scan = 0;
    for (std::size_t p = 0; p < n_poses; ++p) {
        const Pose& pose = walk[p * (walk.size() / n_poses)].pose;
        rays_per_scan = 0;
        for (std::size_t row = 0; row < sensor.elevations.size(); ++row) {
            if (!plan.rows[row]) continue;
            const double e = sensor.elevations[row];
            for (int c0 = 0; c0 < sensor.azimuth_count; c0 += 16) {
                RTCRayHit16 rh;
                std::memset(&rh, 0, sizeof rh);
                for (int k = 0; k < 16; ++k) {
                    const int c = std::min(c0 + k, sensor.azimuth_count - 1);
                    const double az = pose.heading + sensor.azimuth_offset + c * 2 * M_PI / sensor.azimuth_count;
                    rh.ray.org_x[k] = static_cast<float>(pose.x);
                    rh.ray.org_y[k] = static_cast<float>(pose.y);
                    rh.ray.org_z[k] = static_cast<float>(pose.z + sensor.height);
                    rh.ray.dir_x[k] = static_cast<float>(std::cos(e) * std::cos(az));
                    rh.ray.dir_y[k] = static_cast<float>(std::cos(e) * std::sin(az));
                    rh.ray.dir_z[k] = static_cast<float>(std::sin(e));
                    rh.ray.tfar[k] = static_cast<float>(sensor.max_range);
                    rh.ray.mask[k] = 0xFFFFFFFFu;
                    rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
                    rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
                }
                packets[p].push_back(rh);
                rays_per_scan += static_cast<std::size_t>(std::min(16, sensor.azimuth_count - c0));
            }
        }
    }
    alignas(64) int valid[16];
    alignas(64) RTCRayHit16 rh;
    std::size_t i = 0, rays = 0;
    for (auto _ : state) {
        for (const auto& packet : packets[i++ % n_poses]) {
            std::memcpy(&rh, &packet, sizeof rh);
            for (int k = 0; k < 16; ++k) valid[k] = -1;
            RTCIntersectContext ctx;
            rtcInitIntersectContext(&ctx);
            ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            rtcIntersect16(valid, scene, &ctx, &rh);
            benchmark::DoNotOptimize(rh.ray.tfar[0]);
        }
        rays += rays_per_scan;
    }
    state.counters["rays/s"] = benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
}

void BM_RandomModelStep(benchmark::State& state) {
    const World world = World::cross({.tilt_deg = 45});
    auto body = std::make_shared<const BodyCollider>(world.description(), 0.25, 0.1);
    Rng rng(1, Stream::walk);
    RandomWalk walk(body, RobotParams{}, rng, RandomWalk::draw_start(world.description(), *body, rng));
    for (auto _ : state) benchmark::DoNotOptimize(walk.next(1e12));
    state.counters["steps/s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_ScanHorizontal);
BENCHMARK(BM_ScanSpherical)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ScanPlanned, 3d_0_1, std::string("3d-0.1"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ScanPlanned, 3d_3l, std::string("3d-3l"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_EmbreeOnly, 2d, std::string("2d"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_EmbreeOnly, 3d_0_1, std::string("3d-0.1"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_EmbreeOnly, 3d_3l, std::string("3d-3l"))->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RandomModelStep);

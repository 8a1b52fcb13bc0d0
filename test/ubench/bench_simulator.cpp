// Simulator stage: scans (rays per second) and random-walk steps in the paper's 45° arena.
#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>

#include <cmath>
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

// The floor of ray casting: Embree alone on the rays BM_ScanPlanned casts (the same scene flags,
// the same poses, packets of 16 rays column by column over the planned rows, as Lidar::scan fills
// them), with nothing around it: the directions are computed in advance, in float, and a packet
// only copies its own and resets its hit; no ranges refined in double, no returns written.
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

    // Every pose's packets: 16 x, 16 y and 16 z; ray c + rows·j is planned row c of column j, and
    // the idle lanes of a last packet repeat its first ray.
    const LidarSpec& sensor = model.sensor;
    std::vector<double> rows;  // the planned rows' elevations
    for (std::size_t row = 0; row < sensor.elevations.size(); ++row)
        if (plan.rows[row]) rows.push_back(sensor.elevations[row]);
    const std::size_t n_rays = rows.size() * static_cast<std::size_t>(sensor.azimuth_count);
    const std::size_t n_packets = (n_rays + 15) / 16;
    const auto& walk = poses(world);
    std::vector<float> dirs(walk.size() * n_packets * 48);
    for (std::size_t p = 0; p < walk.size(); ++p)
        for (std::size_t lane = 0; lane < n_packets * 16; ++lane) {
            const std::size_t ray = lane < n_rays ? lane : lane / 16 * 16;
            const double e = rows[ray % rows.size()];
            const double az = walk[p].pose.heading + sensor.azimuth_offset +
                              static_cast<double>(ray / rows.size()) * 2 * M_PI / sensor.azimuth_count;
            float* d = &dirs[(p * n_packets + lane / 16) * 48 + lane % 16];
            d[0] = static_cast<float>(std::cos(e) * std::cos(az));
            d[16] = static_cast<float>(std::cos(e) * std::sin(az));
            d[32] = static_cast<float>(std::sin(e));
        }
    alignas(64) int valid[16];
    alignas(64) RTCRayHit16 rh;
    std::memset(&rh, 0, sizeof rh);
    for (int k = 0; k < 16; ++k) {
        rh.ray.mask[k] = 0xFFFFFFFFu;
        rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    const float tfar = static_cast<float>(sensor.max_range) * (1.0f + 1e-6f);
    std::size_t i = 0, rays = 0;
    for (auto _ : state) {
        const Pose& pose = walk[i % walk.size()].pose;
        const float* d = &dirs[i++ % walk.size() * n_packets * 48];
        for (int k = 0; k < 16; ++k) {
            rh.ray.org_x[k] = static_cast<float>(pose.x);
            rh.ray.org_y[k] = static_cast<float>(pose.y);
            rh.ray.org_z[k] = static_cast<float>(pose.z + sensor.height);
        }
        for (std::size_t packet = 0; packet < n_packets; ++packet, d += 48) {
            std::memcpy(rh.ray.dir_x, d, sizeof rh.ray.dir_x);
            std::memcpy(rh.ray.dir_y, d + 16, sizeof rh.ray.dir_y);
            std::memcpy(rh.ray.dir_z, d + 32, sizeof rh.ray.dir_z);
            for (std::size_t k = 0; k < 16; ++k) {
                valid[k] = packet * 16 + k < n_rays ? -1 : 0;
                rh.ray.tfar[k] = tfar;
                rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            }
            RTCIntersectContext ctx;
            rtcInitIntersectContext(&ctx);
            ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            rtcIntersect16(valid, scene, &ctx, &rh);
            benchmark::DoNotOptimize(rh.ray.tfar[0]);
        }
        rays += n_rays;
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
    state.counters["steps/s"] =
        benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
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

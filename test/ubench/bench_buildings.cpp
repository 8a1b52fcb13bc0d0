// Buildings (docs/buildings.md): loading the AWS hospital, an os1-128 scan in it beside Embree alone
// on the same rays (the floor), a tour of its floor. The worlds are read from ../shared/data/gazebo
// beside the source tree; without them these benchmarks are skipped.
#include <benchmark/benchmark.h>
#include <embree3/rtcore.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>

#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/agent/tour.hpp"
#include "bvc3d/config/building.hpp"
#include "bvc3d/sensor/lidar.hpp"
#include "bvc3d/sensor/lidar_models.hpp"

using namespace bvc3d;

namespace {

const std::filesystem::path hospital_dir = std::filesystem::path(BVC3D_SOURCE_DIR).parent_path() / "shared" / "data" /
                                           "gazebo" / "aws-robomaker-hospital-world";

config::BuildingSpec hospital(const char* world) {
    config::BuildingSpec spec;
    spec.file = (hospital_dir / "worlds" / world).string();
    spec.gazebo.skip_missing_models = true;  // the Fuel models the world names are not in the data
    return spec;
}

bool have_data(benchmark::State& state) {
    if (std::filesystem::is_directory(hospital_dir)) return true;
    state.SkipWithError(("no Gazebo worlds in " + hospital_dir.string()).c_str());
    return false;
}

// The one-storey hospital as a World, made once.
const World& hospital_world() {
    static const World w(config::building_world(hospital("hospital.world")));
    return w;
}

// Poses along a walk through the hospital's corridors and rooms.
const std::vector<ModelStep>& hospital_poses() {
    static const auto steps = random_walk(hospital_world(), 0.05, 1);
    return steps;
}

// The whole of `--world hospital_three_floors.world` (with missing models skipped): SDFormat,
// assimp, the floors, the drop edges, the Embree scene.
void BM_LoadHospitalThreeFloors(benchmark::State& state) {
    if (!have_data(state)) return;
    for (auto _ : state) {
        const World w(config::building_world(hospital("hospital_three_floors.world")));
        benchmark::DoNotOptimize(w.mesh().size());
    }
}

void BM_ScanOs128Hospital(benchmark::State& state) {
    if (!have_data(state)) return;
    const World& world = hospital_world();
    LidarSpec spec = lidar_model_spec(*find_lidar_model("os1-128"));
    spec.range_noise_sd = 0;  // the casting alone
    const Lidar lidar(spec);
    const auto& walk = hospital_poses();
    Scan scan;
    std::size_t i = 0, rays = 0;
    for (auto _ : state) {
        lidar.scan(world, walk[i++ % walk.size()].pose, scan);
        benchmark::DoNotOptimize(scan.data());
        rays += spec.beam_count();
    }
    state.counters["rays/s"] = benchmark::Counter(static_cast<double>(rays), benchmark::Counter::kIsRate);
}

// The floor: Embree alone on the same rays (the same scene flags and poses, packets of 16 rays column
// by column as Lidar::scan fills them), directions computed in advance in float, nothing around it.
void BM_EmbreeOnlyOs128Hospital(benchmark::State& state) {
    if (!have_data(state)) return;
    const World& world = hospital_world();
    const LidarSpec sensor = lidar_model_spec(*find_lidar_model("os1-128"));
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

    const std::size_t rows = sensor.elevations.size(), cols = static_cast<std::size_t>(sensor.azimuth_count);
    const std::size_t n_rays = rows * cols, n_packets = (n_rays + 15) / 16;
    const auto& walk = hospital_poses();
    const std::size_t n_poses = std::min<std::size_t>(walk.size(), 64);
    std::vector<float> dirs(n_poses * n_packets * 48);
    for (std::size_t p = 0; p < n_poses; ++p)
        for (std::size_t lane = 0; lane < n_packets * 16; ++lane) {
            const std::size_t ray = lane < n_rays ? lane : lane / 16 * 16;  // idle lanes repeat the first
            const double e = sensor.elevations[ray % rows];
            const double az = walk[p].pose.heading + static_cast<double>(ray / rows) * 2 * M_PI / sensor.azimuth_count;
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
        const std::size_t p = i++ % n_poses;
        const Pose& pose = walk[p].pose;
        const float* d = &dirs[p * n_packets * 48];
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

// A tour of the hospital's floor from its middle: the free-space grid, viewpoints, paths, the drive.
void BM_TourHospital(benchmark::State& state) {
    if (!have_data(state)) return;
    const WorldDescription& w = hospital_world().description();
    for (auto _ : state) benchmark::DoNotOptimize(make_tour(w, 0.25, 0.1).steps.size());
}

}  // namespace

BENCHMARK(BM_LoadHospitalThreeFloors)->Unit(benchmark::kSecond)->Iterations(3);
BENCHMARK(BM_ScanOs128Hospital)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_EmbreeOnlyOs128Hospital)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TourHospital)->Unit(benchmark::kSecond)->Iterations(2);

// Simulator stage: scans (rays per second) and random-walk steps in the paper's 45° arena.
#include <benchmark/benchmark.h>

#include "bvc3d/agent/random_walk.hpp"
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
BENCHMARK(BM_RandomModelStep);

// Model stage: one model step (BVC layer + place cells, learning on) per preset on real scans,
// beside the dense reference (every return x every cell, as a numpy implementation computes it).
#include <benchmark/benchmark.h>

#include "../support/bvc_reference.hpp"
#include "bvc3d/agent/flying_walk.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/config/model_spec.hpp"

using namespace bvc3d;

namespace {

struct Inputs {
    ModelSpec model;
    std::vector<Scan> scans;
};

// Scans along a real walk in the 45° arena.
Inputs inputs(const std::string& preset) {
    Inputs in{model_preset(preset), {}};
    const World world = World::cross({.tilt_deg = 45});
    const Lidar lidar(in.model.sensor);
    const auto walk = random_walk(world, 0.05, 1);
    for (std::size_t i = 0; i < walk.size(); i += walk.size() / 16) in.scans.push_back(lidar.scan(world, walk[i].pose));
    return in;
}

void BM_ModelStep(benchmark::State& state, std::string preset) {
    const Inputs in = inputs(preset);
    const BoundaryVectorLayer layer(in.model.bvc);
    PlaceCellNetwork net(in.model.bvc.n_cells(), in.model.place, 1);
    std::vector<double> rates(layer.n_cells());
    std::size_t i = 0;
    for (auto _ : state) {
        layer.rates(in.scans[i++ % in.scans.size()], rates);
        benchmark::DoNotOptimize(net.step(rates, true).data());
    }
}

// What a trial does per model step on `walk`: cast the rows the model needs, BVC rates, place cells
// learning, 16 steps at a time as the trial runner steps them (one iteration is one step; every 16th
// also runs the place cells' block). When the pruning bound fails (almost nothing in view) the scan is
// read again in full, as the trial runner does, if `fallback`; otherwise the benchmark stops with an
// error.
void planned_steps(benchmark::State& state, const ModelSpec& model, const World& world,
                   const std::vector<ModelStep>& walk, bool fallback) {
    constexpr std::size_t block = 16;
    const Lidar lidar(model.sensor);
    const BoundaryVectorLayer layer(model.bvc);
    const auto plan = layer.plan(model.sensor);
    PlaceCellNetwork net(model.bvc.n_cells(), model.place, 1);
    const std::size_t n = layer.n_cells();
    std::vector<double> rates(block * n);
    const std::vector<char> learn(block, 1);
    Scan scan;
    std::size_t i = 0, rows = 0;
    for (char r : plan.rows) rows += r != 0;
    for (auto _ : state) {
        const auto& s = walk[i % walk.size()];
        const std::span<double> out(rates.data() + (i % block) * n, n);
        lidar.scan(world, s.pose, scan, {}, plan.rows);
        if (!layer.rates_pruned(scan, plan, out)) {
            if (!fallback) state.SkipWithError("pruning bound failed");
            else layer.rates(lidar.scan(world, s.pose), out);
        }
        if (++i % block == 0) benchmark::DoNotOptimize(net.step_block(rates, learn).data());
    }
    state.counters["rays"] = static_cast<double>(rows * static_cast<std::size_t>(model.sensor.azimuth_count));
}

void BM_FullStep(benchmark::State& state, std::string preset) {
    const World world = World::cross({.tilt_deg = 45});
    planned_steps(state, model_preset(preset), world, random_walk(world, 0.1, 1), false);
}

void BM_BvcOnly(benchmark::State& state, std::string preset) {
    const Inputs in = inputs(preset);
    const BoundaryVectorLayer layer(in.model.bvc);
    std::vector<double> rates(layer.n_cells());
    std::size_t i = 0;
    for (auto _ : state) {
        layer.rates(in.scans[i++ % in.scans.size()], rates);
        benchmark::DoNotOptimize(rates.data());
    }
}

void BM_PlaceCellsOnly(benchmark::State& state) {
    const Inputs in = inputs("3d-0.2");
    const BoundaryVectorLayer layer(in.model.bvc);
    PlaceCellNetwork net(in.model.bvc.n_cells(), in.model.place, 1);
    std::vector<std::vector<double>> rates(in.scans.size(), std::vector<double>(layer.n_cells()));
    for (std::size_t k = 0; k < in.scans.size(); ++k) layer.rates(in.scans[k], rates[k]);
    std::size_t i = 0;
    for (auto _ : state) benchmark::DoNotOptimize(net.step(rates[i++ % rates.size()], state.range(0) != 0).data());
}

// The dense baseline: the literal equations for the BVCs, a double-precision matrix-vector
// product and rank-1 update for the place cells.
void BM_DenseReferenceStep(benchmark::State& state, std::string preset) {
    const Inputs in = inputs(preset);
    const int nb = in.model.bvc.n_cells(), np = in.model.place.n_place;
    std::vector<double> W(static_cast<std::size_t>(np) * nb, 0.25), s(np, 0.0), v(np, 0.0);
    const auto& p = in.model.place;
    std::size_t i = 0;
    for (auto _ : state) {
        const auto vb = reference::bvc_rates(in.model.bvc, in.scans[i++ % in.scans.size()]);
        double sum_b = 0, sum_p = 0;
        for (double x : vb) sum_b += x;
        for (double x : v) sum_p += x;
        for (int a = 0; a < np; ++a) {
            double drive = 0;
            for (int b = 0; b < nb; ++b) drive += W[static_cast<std::size_t>(a) * nb + b] * vb[b];
            s[a] += p.dt_over_tau * (-s[a] + drive - p.gamma_pb * sum_b - p.gamma_pp * sum_p);
        }
        for (int a = 0; a < np; ++a) v[a] = std::tanh(p.gain * std::max(s[a], 0.0));
        for (int a = 0; a < np; ++a)
            for (int b = 0; b < nb; ++b) {
                double& w = W[static_cast<std::size_t>(a) * nb + b];
                w += p.eta * v[a] * (vb[b] - v[a] * w / p.alpha_pb);
            }
        benchmark::DoNotOptimize(v.data());
    }
}

// A flying agent's model step in the flight room: the full spherical scan (all 16 200 rays, every row
// cast whatever the model needs), the BVC layer and 250 place cells learning (docs/flying.md#speed).
void BM_FlyingFullScanStep(benchmark::State& state, std::string preset) {
    const ModelSpec model = model_preset(preset);
    const World world(flight_room());
    const Lidar lidar(model.sensor);
    const BoundaryVectorLayer layer(model.bvc);
    PlaceCellNetwork net(model.bvc.n_cells(), model.place, 1);
    const auto walk = flying_walk(world, 0.1, 1);
    std::vector<double> rates(layer.n_cells());
    Scan scan;
    std::size_t i = 0;
    for (auto _ : state) {
        lidar.scan(world, walk[i++ % walk.size()].pose, scan);
        layer.rates(scan, rates);
        benchmark::DoNotOptimize(net.step(rates, true).data());
    }
}

// What a flying trial does per model step with the default level head: cast the rows the model
// needs (the plan), BVC rates, 250 place cells learning.
void BM_FlyingStep(benchmark::State& state, std::string preset) {
    const World world(flight_room());
    planned_steps(state, model_preset(preset), world, flying_walk(world, 0.1, 1), true);
}

// The full spherical scan alone (16 200 rays in the flight room): the ray-casting share of the above.
void BM_FlyingFullScanOnly(benchmark::State& state) {
    const World world(flight_room());
    const Lidar lidar(LidarSpec::spherical_full());
    const auto walk = flying_walk(world, 0.1, 1);
    Scan scan;
    std::size_t i = 0;
    for (auto _ : state) {
        lidar.scan(world, walk[i++ % walk.size()].pose, scan);
        benchmark::DoNotOptimize(scan.data());
    }
    state.counters["rays/s"] =
        benchmark::Counter(16200.0 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_FlyingFullScanOnly)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FlyingStep, fly_up, std::string("fly-up"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FlyingStep, fly_5l, std::string("fly-5l"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FlyingStep, fly_9l, std::string("fly-9l"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FlyingFullScanStep, fly_5l, std::string("fly-5l"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ModelStep, 2d, std::string("2d"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ModelStep, 3d_0_1, std::string("3d-0.1"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ModelStep, 3d_0_2, std::string("3d-0.2"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ModelStep, 3d_3l, std::string("3d-3l"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_ModelStep, 2d_8beam, std::string("2d-8beam"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FullStep, 2d, std::string("2d"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FullStep, 3d_0_1, std::string("3d-0.1"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FullStep, 3d_0_2, std::string("3d-0.2"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FullStep, 3d_3l, std::string("3d-3l"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_FullStep, 2d_8beam, std::string("2d-8beam"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_BvcOnly, 2d, std::string("2d"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_BvcOnly, 3d_3l, std::string("3d-3l"))->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PlaceCellsOnly)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DenseReferenceStep, 2d, std::string("2d"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DenseReferenceStep, 3d_0_1, std::string("3d-0.1"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DenseReferenceStep, 3d_0_2, std::string("3d-0.2"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DenseReferenceStep, 3d_3l, std::string("3d-3l"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DenseReferenceStep, 2d_8beam, std::string("2d-8beam"))->Unit(benchmark::kMillisecond);

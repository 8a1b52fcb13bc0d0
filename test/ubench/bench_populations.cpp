// Population stage: the authors' multiscale model (ms-2d, ms-3d: three BVC layers, three grid modules, HD cells,
// 3 500 place cells fed by BVCs and grid cells) stepped as a trial steps it, learning on; and a large place-cell
// network (10 000 place cells × 4 000 BVCs, 160 MB of weights) beside the floor of streaming its weights from memory.
#include <benchmark/benchmark.h>

#include <cstring>
#include <numeric>
#include <random>

#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/experiment/model_network.hpp"
#include "bvc3d/place/place_cell_network.hpp"
#include "bvc3d/place/place_kernels.hpp"

using namespace bvc3d;

namespace {

// One iteration is one model step through the whole network (ray cast, every population), as the trial runner
// steps it: blocked populations every 16 steps.
void BM_MultiscaleModelStep(benchmark::State& state, std::string preset) {
    const World world = World::cross({.tilt_deg = 0});
    TrialConfig trial;
    trial.model = model_preset(preset);
    trial.seed = 1;
    ModelNetwork models(&world, {trial}, {}, false);
    const auto walk = random_walk(world, 0.2, 1);
    std::int64_t i = 0;
    for (auto _ : state) {
        models.network.step(walk[static_cast<std::size_t>(i) % walk.size()], i, true, false);
        ++i;
    }
    models.network.flush();
    state.counters["steps/s"] =
        benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

// n_place × n_bvc = 10 000 × 4 000, learning off or on, in blocks of 16 steps (as trials step it) or one step at a
// time (Arg 1); one iteration is one step.
std::vector<double> sparse_bvc_rates(std::size_t steps, std::size_t n, std::uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<double> r(steps * n);
    for (auto& x : r) x = u(rng) < 0.1 ? 0.5 * u(rng) : 0.0;  // a tenth of the BVCs active, as in the arena
    return r;
}

void BM_LargePlaceNetwork(benchmark::State& state) {
    const bool learn = state.range(0) != 0, single = state.range(1) != 0;
    constexpr int n_bvc = 4000;
    PlaceParams p;
    p.n_place = 10000;
    PlaceCellNetwork net(n_bvc, p, 1);
    constexpr std::size_t block = 16;
    const auto rates = sparse_bvc_rates(block, n_bvc, 2);
    const std::vector<char> flags(block, learn ? 1 : 0);
    std::size_t i = 0;
    for (auto _ : state) {
        if (single) {
            benchmark::DoNotOptimize(net.step(std::span(rates).subspan((i % block) * n_bvc, n_bvc), learn).data());
        } else if (i % block == 0) {
            benchmark::DoNotOptimize(net.step_block(rates, flags).data());
        }
        ++i;
    }
    state.counters["weights_MB"] = 4.0 * p.n_place * n_bvc / 1e6;
}

// The floor: one pass over 160 MB of floats (the weights of the network above), summed by the network's own SIMD
// kernel (the widest instruction set the CPU has).
void BM_StreamWeightsOnce(benchmark::State& state) {
    std::vector<float> w(static_cast<std::size_t>(10000) * 4000, 0.25f);
    for (auto _ : state) benchmark::DoNotOptimize(kernels::sum8(w.data(), w.size()));
    state.counters["GB/s"] =
        benchmark::Counter(4.0 * static_cast<double>(w.size()) * state.iterations() / 1e9, benchmark::Counter::kIsRate);
}

// The floor read by glibc's memchr looking for a byte that is not there: its wide SIMD loop reads every byte once
// and does nothing else, so it runs at the rate memory delivers. Arg MB: 160 (the network's weights, which fit in
// this machine's 300 MiB L3) and 1 600 (ten times that: main memory's streaming rate).
void BM_StreamWeightsMemchr(benchmark::State& state) {
    const auto bytes = static_cast<std::size_t>(state.range(0)) * 1000000;
    const std::vector<unsigned char> w(bytes, 0x3e);  // the high byte of 0.25f
    for (auto _ : state) benchmark::DoNotOptimize(std::memchr(w.data(), 0x01, w.size()));
    state.counters["GB/s"] =
        benchmark::Counter(static_cast<double>(bytes) * state.iterations() / 1e9, benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK_CAPTURE(BM_MultiscaleModelStep, ms_2d, std::string("ms-2d"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_MultiscaleModelStep, ms_3d, std::string("ms-3d"))->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_MultiscaleModelStep, paper_2d, std::string("2d"))->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LargePlaceNetwork)
    ->Args({0, 1})
    ->Args({0, 0})
    ->Args({1, 1})
    ->Args({1, 0})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(1.0);
BENCHMARK(BM_StreamWeightsOnce)->Unit(benchmark::kMillisecond)->MinTime(1.0);
BENCHMARK(BM_StreamWeightsMemchr)->Arg(160)->Arg(1600)->Unit(benchmark::kMillisecond)->MinTime(1.0);

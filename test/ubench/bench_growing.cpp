// Population stage: the growing place-cell network's step (population/growing_place_cells.hpp) beside the paper's
// network of as many cells (place/place_cell_network.hpp), learning on, 960 BVCs. The growing network is first
// grown to its budget (a cell per hand-made place), so a step is the paper's step plus the growing one's own work:
// copying the rates out and, every sample_every-th step, the recruitment check.
#include <benchmark/benchmark.h>

#include <cmath>

#include "bvc3d/population/growing_place_cells.hpp"

using namespace bvc3d;

namespace {

constexpr int kBvc = 960;

// Hand-made BVC vectors of distinct places: a boundary lighting 30 neighbouring cells, a weak background.
std::vector<std::vector<double>> places(int n) {
    std::vector<std::vector<double>> out(n, std::vector<double>(kBvc, 0.0));
    for (int k = 0; k < n; ++k) {
        const int start = (k * 389) % (kBvc - 30);
        for (int j = 0; j < 30; ++j) out[k][start + j] = 0.5 * std::exp(-0.5 * (j - 15) * (j - 15) / 36.0);
        for (int j = 0; j < kBvc; ++j) out[k][j] += 0.002 * ((j * 7 + k * 13) % 10);
    }
    return out;
}

// The growing network grown through `places` hand-made places (recruiting at each where no cell fires at 1.0), its
// budget the cells it recruits there: it recruits no more while it is timed.
GrowingPlaceCells grown(int places_, const std::vector<std::vector<double>>& in) {
    GrowingParams g;
    g.budget = places_;
    g.threshold = 1.0;
    g.sample_every = 1;
    GrowingPlaceCells probe(kBvc, PlaceParams{}, g, 1);
    for (const auto& b : in) probe.step(b, true);
    g.budget = probe.n_cells();
    GrowingPlaceCells net(kBvc, PlaceParams{}, g, 1);
    for (const auto& b : in) net.step(b, true);
    return net;
}

void BM_GrowingStep(benchmark::State& state) {
    const auto in = places(static_cast<int>(state.range(0)));
    GrowingPlaceCells net = grown(static_cast<int>(state.range(0)), in);
    std::size_t i = 0;
    for (auto _ : state) benchmark::DoNotOptimize(net.step(in[i++ % in.size()], true).data());
    state.counters["cells"] = net.n_cells();
}

// The baseline: the paper's network with the grown network's cells and weights, the same inputs.
void BM_PaperStepSameWeights(benchmark::State& state) {
    const auto in = places(static_cast<int>(state.range(0)));
    const GrowingPlaceCells net0 = grown(static_cast<int>(state.range(0)), in);
    PlaceParams p;
    p.n_place = net0.n_cells();
    PlaceCellNetwork net(kBvc, p, 1);
    net.set_weights(net0.weights());
    std::size_t i = 0;
    for (auto _ : state) benchmark::DoNotOptimize(net.step(in[i++ % in.size()], true).data());
    state.counters["cells"] = p.n_place;
}

}  // namespace

BENCHMARK(BM_GrowingStep)->Arg(250)->Arg(2000)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PaperStepSameWeights)->Arg(250)->Arg(2000)->Unit(benchmark::kMicrosecond);

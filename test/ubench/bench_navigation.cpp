// Navigation (docs/navigation.md#speed): one exploitation decision — the rollouts of every HD direction through a
// learned adjacency — and a whole decision with the sensor, BVCs and place cells, for the paper's 250 place cells and
// for adjacencies of the authors' multiscale sizes (2 000 / 1 000 / 500 cells per scale; learned here on a
// synthetic walk of sparse place fields, so that the figures do not depend on a long learning walk). The second
// argument p: the products read the sparse copy with prune = 10^(−p/2) (p = 2: 10⁻¹, 3: 3.2·10⁻², 4: 10⁻²; p = 0:
// prune 0, every non-zero weight, the exact products); the third T: steps of each rollout (SPEC: 3); counters give
// the copy's entries and bytes against the dense n_hd·n² float32.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "bvc3d/bvc/boundary_vector_layer.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/core/random.hpp"
#include "bvc3d/navigation/packed_adjacency.hpp"
#include "bvc3d/navigation/replay.hpp"
#include "bvc3d/navigation/rollouts.hpp"
#include "bvc3d/navigation/scale_mix.hpp"
#include "bvc3d/navigation/sparse_adjacency.hpp"
#include "bvc3d/place/place_cell_network.hpp"
#include "bvc3d/sensor/lidar.hpp"

using namespace bvc3d;

namespace {

// n cells with fields on a 20 × 20 m floor; rates of a point: the cells within 1 m, Gaussian.
struct Fields {
    std::vector<double> cx, cy;
    explicit Fields(int n) {
        Rng rng(1, Stream::walk);
        for (int i = 0; i < n; ++i) cx.push_back(rng.uniform(-10, 10)), cy.push_back(rng.uniform(-10, 10));
    }
    std::vector<double> rates(double x, double y, double width) const {
        std::vector<double> v(cx.size(), 0.0);
        for (std::size_t i = 0; i < v.size(); ++i) {
            const double d2 = (cx[i] - x) * (cx[i] - x) + (cy[i] - y) * (cy[i] - y);
            if (d2 < 4 * width * width) v[i] = std::exp(-d2 / (2 * width * width));
        }
        return v;
    }
};

struct Learned {
    Fields fields;
    HdAdjacency adj;
    std::vector<double> w;
    double width;
    explicit Learned(int n) : Learned(n, n >= 2000 ? 0.5 : n >= 1000 ? 1.0 : 1.5) {}
    Learned(int n, double width_) : fields(n), adj(n), width(width_) {
        Rng rng(2, Stream::walk);
        double x = 0, y = 0, h = 0;
        for (int t = 0; t < 20000; ++t) {
            h += rng.normal(0, 0.3);
            x = std::clamp(x + 0.144 * std::cos(h), -10.0, 10.0), y = std::clamp(y + 0.144 * std::sin(h), -10.0, 10.0);
            adj.learn(fields.rates(x, y, width), hd_rates(h), false);
        }
        const auto v = fields.rates(7, 7, width);
        w = replay(adj, static_cast<int>(std::max_element(v.begin(), v.end()) - v.begin()));
    }
};

Learned& learned(int n) {
    static std::map<int, std::unique_ptr<Learned>> cache;
    auto& l = cache[n];
    if (!l) l = std::make_unique<Learned>(n);
    return *l;
}

double prune_of(const benchmark::State& state) {
    return state.range(1) ? std::pow(10.0, -double(state.range(1)) / 2) : 0;
}
RewardParams rollout_of(const benchmark::State& state) {
    RewardParams p;
    p.rollout_steps = static_cast<int>(state.range(2));
    return p;
}

void BM_DirectionChoice(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    const Learned& l = learned(n);
    const SparseAdjacency sparse(l.adj, prune_of(state));
    const auto v = l.fields.rates(-3, -2, l.width);
    const RewardParams p = rollout_of(state);
    for (auto _ : state) benchmark::DoNotOptimize(direction_returns(sparse, l.w, v, p));
    state.counters["decisions/s"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
    state.counters["entries"] = double(sparse.entries());
    state.counters["MB"] = sparse.bytes() / 1e6;
    state.counters["dense_MB"] = HdAdjacency::bytes(n, l.adj.n_hd()) / 1e6;
}
BENCHMARK(BM_DirectionChoice)->ArgsProduct({{250, 1000, 2000}, {0, 4}, {3, 1}})->Unit(benchmark::kMicrosecond);

// The authors' multiscale size: three scales of 2 000 / 1 000 / 500 place cells, each scale's rollouts and the
// scales' combination (combine_scales: softmaxes over 8 and 3 numbers), as navigation decides; through the float32
// sparse copies (Copy = SparseAdjacency) or the packed ones (PackedAdjacency: `adjacency: {rollout_weights:
// float16}`, one pattern for the 8 directions, 16-bit weights, every direction in one pass).
// The benchmark's loop: one decision at (-3, -2) a lap, every scale's rollouts through its copy and the scales'
// combination, as navigation decides.
template <class Copy>
void decide(benchmark::State& state, const std::vector<const Learned*>& scales, const std::vector<Copy>& copies,
            const RewardParams& p) {
    std::vector<std::vector<double>> v;
    for (const Learned* l : scales) v.push_back(l->fields.rates(-3, -2, l->width));
    const std::vector<char> allowed(8, 1);
    std::vector<std::vector<double>> returns(scales.size());
    std::vector<double> scores;
    for (auto _ : state) {
        for (std::size_t s = 0; s < scales.size(); ++s)
            returns[s] = direction_returns(copies[s], scales[s]->w, v[s], p);
        benchmark::DoNotOptimize(combine_scales(returns, allowed, p, scores));
    }
    state.counters["decisions/s"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}

template <class Copy>
void BM_DirectionChoiceMultiscale(benchmark::State& state) {
    std::vector<const Learned*> scales;
    std::vector<Copy> copies;
    double bytes = 0, entries = 0, dense = 0;
    for (int n : {2000, 1000, 500}) {
        scales.push_back(&learned(n));
        copies.emplace_back(scales.back()->adj, prune_of(state));
        bytes += copies.back().bytes(), entries += double(copies.back().entries());
        dense += HdAdjacency::bytes(n, 8);
    }
    decide(state, scales, copies, rollout_of(state));
    state.counters["MB"] = bytes / 1e6;
    state.counters["entries"] = entries;
    state.counters["dense_MB"] = dense / 1e6;
}
BENCHMARK(BM_DirectionChoiceMultiscale<SparseAdjacency>)
    ->Name("BM_DirectionChoiceMultiscale")
    ->ArgsProduct({{3500}, {0, 2, 3, 4}, {3, 1}})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DirectionChoiceMultiscale<PackedAdjacency>)
    ->Name("BM_DirectionChoiceMultiscaleHalf")
    ->ArgsProduct({{3500}, {3, 4}, {3}})
    ->Unit(benchmark::kMicrosecond);

// The packed copy's tiles (kernels::HalfTiles): the decision above at prune 10⁻² with panels of `panel` cells (the
// default 512) against whole rows (panel 65 536: one tile a block of rows, the layout before the tiles). The same
// bits either way; run with --benchmark_enable_random_interleaving for a paired comparison.
void BM_DirectionChoiceTiles(benchmark::State& state) {
    const int panel = static_cast<int>(state.range(0));
    std::vector<const Learned*> scales;
    std::vector<PackedAdjacency> copies;
    for (int n : {2000, 1000, 500}) {
        scales.push_back(&learned(n));
        copies.emplace_back(scales.back()->adj, 0.01, panel);
    }
    decide(state, scales, copies, RewardParams{});
}
BENCHMARK(BM_DirectionChoiceTiles)->Arg(512)->Arg(65536)->Unit(benchmark::kMicrosecond);

// One learning step of the adjacency (traces, the active rows and columns of 8 matrices, the decay) on the synthetic
// walk's place rates, for the multiscale sizes: what learning adds to each model step of navigation.
void BM_AdjacencyLearn(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    const Fields fields(n);
    const double width = n >= 2000 ? 0.5 : n >= 1000 ? 1.0 : 1.5;
    std::vector<std::vector<double>> rates, hd;
    Rng rng(2, Stream::walk);
    double x = 0, y = 0, h = 0;
    for (int t = 0; t < 256; ++t) {
        h += rng.normal(0, 0.3);
        x = std::clamp(x + 0.144 * std::cos(h), -10.0, 10.0), y = std::clamp(y + 0.144 * std::sin(h), -10.0, 10.0);
        rates.push_back(fields.rates(x, y, width)), hd.push_back(hd_rates(h));
    }
    HdAdjacency adj(n);
    std::size_t t = 0;
    for (auto _ : state) {
        adj.learn(rates[t % rates.size()], hd[t % rates.size()], false);
        ++t;
    }
    state.counters["steps/s"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_AdjacencyLearn)->Arg(500)->Arg(1000)->Arg(2000)->Unit(benchmark::kMicrosecond);

// A whole decision of the paper's 2d model: scan, BVCs, one place-cell step, the rollouts.
void BM_DecisionWithModel(benchmark::State& state) {
    const World world = World::cross();
    const ModelSpec model = model_preset("2d");
    const Lidar lidar(model.sensor);
    const BoundaryVectorLayer layer(model.bvc);
    PlaceCellNetwork net(static_cast<int>(layer.n_cells()), model.place, 0);
    const Learned& l = learned(250);
    const SparseAdjacency sparse(l.adj);
    Scan scan;
    std::vector<double> bvc(layer.n_cells());
    for (auto _ : state) {
        lidar.scan(world, Pose::on_floor(-3, -2, 0), scan);
        layer.rates(scan, bvc);
        const auto p = net.step(bvc, false);
        const std::vector<double> v(p.begin(), p.end());
        benchmark::DoNotOptimize(direction_returns(sparse, l.w, v));
    }
    state.counters["decisions/s"] = benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DecisionWithModel)->Unit(benchmark::kMicrosecond);

}  // namespace

// The growing place-cell network (issue 29; docs/model-reference.md#growing-place-cells) as a population: blocks of
// steps give the bits of single steps, a checkpoint continues exactly, and a model's YAML runs it in a trial. Its
// rule against a numpy transcription and the paper's network: test/python/test_growing_place_cells.py.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/experiment/experiment.hpp"
#include "bvc3d/experiment/trial_runner.hpp"
#include "bvc3d/population/growing_place_cells.hpp"

using namespace bvc3d;

namespace {

constexpr int kBvc = 48;

// Hand-made BVC vectors: the agent dwells `dwell` steps at each of `places` places, each lighting a block of BVCs.
std::vector<double> tour(int places, int dwell) {
    std::vector<double> out;
    for (int k = 0; k < places; ++k) {
        std::vector<double> b(kBvc, 0.0);
        const int start = (k * 17) % (kBvc - 8);
        for (int j = 0; j < 8; ++j) b[start + j] = 0.5 * std::exp(-0.5 * (j - 4) * (j - 4) / 4.0);
        for (int j = 0; j < kBvc; ++j) b[j] += 0.01 * ((j * 7 + k * 13) % 10);
        for (int d = 0; d < dwell; ++d) out.insert(out.end(), b.begin(), b.end());
    }
    return out;
}

GrowingParams small() {
    GrowingParams g;
    g.budget = 70;  // past the first capacity (64): the network regrows its rows once
    g.n_initial = 3;
    g.threshold = 0.95;
    g.sample_every = 3;
    return g;
}

// Steps `net` through `bvc` in blocks of `block` via the Population interface; returns every step's rates.
std::vector<double> by_blocks(GrowingPlaceCells& net, const std::vector<double>& bvc, std::size_t block,
                              std::vector<char>& learn, std::size_t from = 0, std::size_t to = 0) {
    const std::size_t steps = bvc.size() / kBvc, end = to ? to : steps;
    std::vector<double> out;
    std::vector<ModelStep> pad(block);
    for (std::size_t t = from; t < end; t += block) {
        const std::size_t n = std::min(block, end - t);
        std::vector<double> rates(n * net.size());
        const std::span<const double> in(bvc.data() + t * kBvc, n * kBvc);
        const std::span<const double> inputs[] = {in};
        net.step(StepBlock{{pad.data(), n}, {learn.data() + t, n}, static_cast<std::int64_t>(t)}, inputs, rates);
        out.insert(out.end(), rates.begin(), rates.end());
    }
    return out;
}

}  // namespace

TEST(GrowingPlaceCells, BlocksGiveTheBitsOfSingleSteps) {
    const auto bvc = tour(80, 4);
    const std::size_t steps = bvc.size() / kBvc;
    std::vector<char> learn(steps, 1);
    for (std::size_t t = 50; t < 60; ++t) learn[t] = 0;
    GrowingPlaceCells single(kBvc, PlaceParams{}, small(), 9);
    std::vector<double> expect;
    for (std::size_t t = 0; t < steps; ++t) {
        const auto v = single.step(std::span<const double>(bvc.data() + t * kBvc, kBvc), learn[t] != 0);
        expect.insert(expect.end(), v.begin(), v.end());
    }
    ASSERT_GT(single.n_cells(), 64);
    ASSERT_EQ(single.n_cells(), 70);  // the budget stops it
    for (std::size_t block : {1u, 8u, 13u}) {
        GrowingPlaceCells net(kBvc, PlaceParams{}, small(), 9);
        EXPECT_EQ(by_blocks(net, bvc, block, learn), expect) << block;
        EXPECT_EQ(net.weights(), single.weights()) << block;
        EXPECT_EQ(net.recruited_at(), single.recruited_at()) << block;
    }
}

TEST(GrowingPlaceCells, ACheckpointContinuesExactly) {
    const auto bvc = tour(60, 4);
    const std::size_t steps = bvc.size() / kBvc;
    std::vector<char> learn(steps, 1);
    GrowingPlaceCells whole(kBvc, PlaceParams{}, small(), 2);
    const auto expect = by_blocks(whole, bvc, 8, learn);
    GrowingPlaceCells first(kBvc, PlaceParams{}, small(), 2);
    auto got = by_blocks(first, bvc, 8, learn, 0, 101);
    ASSERT_GT(first.n_cells(), 3);
    ASSERT_LT(first.n_cells(), whole.n_cells());
    GrowingPlaceCells second(kBvc, PlaceParams{}, small(), 77);  // another seed: everything comes from the state
    second.restore(first.state());
    const auto rest = by_blocks(second, bvc, 8, learn, 101);
    got.insert(got.end(), rest.begin(), rest.end());
    EXPECT_EQ(got, expect);
    EXPECT_EQ(second.weights(), whole.weights());
    // A state that does not fit is refused before anything changes.
    auto bad = first.state();
    for (auto& a : bad)
        if (a.name == "counts") std::get<std::vector<double>>(a.values)[0] = 71;
    EXPECT_THROW(second.restore(bad), InputError);
    EXPECT_EQ(second.weights(), whole.weights());
}

TEST(GrowingPlaceCells, AModelsYamlRunsItInATrial) {
    const auto model = config::model_from_yaml(config::YamlView::load_string(R"(
base: 2d
populations:
  - {name: grow, kind: growing-place, inputs: [bvc], budget: 40, sample_every: 5, threshold: 0.2}
)",
                                                                             "model.yaml"));
    ASSERT_EQ(model.populations.size(), 1u);
    TrialConfig t;
    t.world = WorldSpec{"cross", 0, "+x+y"};
    t.model = model;
    t.seed = 5;
    t.protocol.explore_hours = t.protocol.sample_hours = 0.05;
    const GroupResult r = run_trial_group({t});
    const auto& grow = r.models[0].populations.at(0);
    EXPECT_EQ(grow.cells, 40u);
    ASSERT_EQ(grow.rates.size(), r.t.size() * 40);
    const auto& at = std::get<std::vector<double>>(grow.kept.at(1).values);
    const auto cells = static_cast<std::size_t>(std::count_if(at.begin(), at.end(), [](double a) { return a >= 0; }));
    EXPECT_GT(cells, 2u);
    EXPECT_LE(cells, 40u);
    for (std::size_t j = 0; j < r.t.size(); ++j)
        for (std::size_t c = cells; c < 40; ++c) ASSERT_EQ(grow.rates[j * 40 + c], 0.0f);
    // The model's own place cells are the paper's: the same as without the population.
    TrialConfig plain = t;
    plain.model.populations.clear();
    EXPECT_EQ(run_trial_group({plain}).models[0].rates, r.models[0].rates);
    EXPECT_EQ(run_trial_group({t}).models[0].populations[0].rates, grow.rates);  // deterministic
}

// Head-direction and grid cells (issue 29; docs/model-reference.md#head-direction-cells, #grid-cells): hand-made
// inputs whose rates follow from geometry, path integration's determinism across blocks and checkpoints, and the
// `populations:` list of a model's YAML running in a trial.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/config/population_kinds.hpp"
#include "bvc3d/experiment/experiment.hpp"
#include "bvc3d/experiment/trial_runner.hpp"
#include "bvc3d/population/grid_cells.hpp"
#include "bvc3d/population/head_direction_cells.hpp"

using namespace bvc3d;
constexpr double kPi = std::numbers::pi;

namespace {

std::vector<double> run(Population& p, const std::vector<ModelStep>& steps, std::int64_t first = 0) {
    std::vector<double> out(steps.size() * p.size());
    const std::vector<char> learn(steps.size(), 0);
    p.step(StepBlock{steps, learn, first}, {}, out);
    return out;
}

ModelStep at(double x, double y, double z = 0, double heading = 0) {
    ModelStep s;
    s.pose = Pose{x, y, z, heading, 0, 0};
    return s;
}

std::vector<ModelStep> walk(int n) {
    std::vector<ModelStep> steps;
    for (int i = 0; i < n; ++i) steps.push_back(at(0.144 * i * std::cos(0.3 * i), 0.1 * i, 0, 0.3 * i));
    return steps;
}

}  // namespace

TEST(HeadDirectionCells, PlanarCellsAreCosinesOfTheHeading) {
    HeadDirectionCells hd(HeadDirectionParams{});
    ASSERT_EQ(hd.size(), 8u);
    const auto v = run(hd, {at(0, 0, 0, 0), at(0, 0, 0, kPi / 2)});
    const double expect0[8] = {1, std::sqrt(0.5), 0, -std::sqrt(0.5), -1, -std::sqrt(0.5), 0, std::sqrt(0.5)};
    for (int k = 0; k < 8; ++k) {
        EXPECT_NEAR(v[k], expect0[k], 1e-12) << k;
        EXPECT_NEAR(v[8 + (k + 2) % 8], expect0[k], 1e-12) << k;  // a quarter turn moves the bump two cells on
    }
}

TEST(HeadDirectionCells, TheIcosahedronsFacesAreTwentyEvenlySpreadDirections) {
    const auto& faces = hd::icosahedron_faces();
    Vec3 sum(0, 0, 0);
    for (std::size_t i = 0; i < faces.size(); ++i) {
        EXPECT_NEAR(faces[i].norm(), 1.0, 1e-12);
        sum += faces[i];
        int neighbours = 0, antipodes = 0;
        for (std::size_t j = 0; j < faces.size(); ++j) {
            const double c = faces[i].dot(faces[j]);
            neighbours += std::abs(c - std::sqrt(5.0) / 3.0) < 1e-9;  // faces sharing an edge: the dihedral angle
            antipodes += std::abs(c + 1.0) < 1e-9;
        }
        EXPECT_EQ(neighbours, 3) << i;
        EXPECT_EQ(antipodes, 1) << i;
    }
    EXPECT_LT(sum.norm(), 1e-12);
}

TEST(HeadDirectionCells, FlyingCellsReadTheDirectionFlown) {
    HeadDirectionParams p;
    p.space = HdSpace::spherical;
    HeadDirectionCells hd(p);
    ASSERT_EQ(hd.size(), 20u);
    // First step: the pose's own yaw (pitch 0); then the displacements (0, 0, 1) and (1, 1, 0)/√2.
    const auto v = run(hd, {at(1, 1, 1, kPi), at(1, 1, 2), at(2, 2, 2)});
    const auto& u = hd::icosahedron_faces();
    for (int k = 0; k < 20; ++k) {
        EXPECT_NEAR(v[k], -u[k].x(), 1e-12);
        EXPECT_NEAR(v[20 + k], u[k].z(), 1e-12);
        EXPECT_NEAR(v[40 + k], (u[k].x() + u[k].y()) / std::sqrt(2.0), 1e-12);
    }
    // A checkpoint carries the last position: the next step's direction is the same after a restore.
    HeadDirectionCells again(p);
    again.restore(hd.state());
    EXPECT_EQ(run(again, {at(2, 2, 5)}), run(hd, {at(2, 2, 5)}));
}

TEST(GridCells, FieldsPeakAtThePhaseAndOnTheLatticeAndVanishBetween) {
    GridParams p;
    p.spacing = 5.5;
    p.orientation = 0.2;
    const auto cells = grid::module(p, 7);
    ASSERT_EQ(cells.size(), 800u);
    const double centre_gap = 2 * p.spacing / std::sqrt(3.0);
    for (int c : {0, 1, 7, 8, 799}) {
        const auto& cell = cells[c];
        EXPECT_NEAR(cell.orientation, 0.2 + (c % 8) * kPi / 4, 1e-12);
        EXPECT_NEAR(grid::interference(cell, p.spacing, cell.tx, cell.ty), 1.0, 1e-12);
        for (int k = 0; k < 6; ++k) {  // the six neighbouring field centres, at 30° + k·60° from the waves
            const double a = cell.orientation + kPi / 6 + k * kPi / 3;
            const double x = cell.tx + centre_gap * std::cos(a), y = cell.ty + centre_gap * std::sin(a);
            EXPECT_NEAR(grid::interference(cell, p.spacing, x, y), 1.0, 1e-9) << c << " " << k;
            // Halfway to a neighbour the three waves disagree: z = −1/3 there... and the rate is 0.
            const double hx = cell.tx + centre_gap / 2 * std::cos(a), hy = cell.ty + centre_gap / 2 * std::sin(a);
            EXPECT_NEAR(grid::interference(cell, p.spacing, hx, hy), -1.0 / 3.0, 1e-9);
            EXPECT_EQ(grid::rate(grid::interference(cell, p.spacing, hx, hy)), 0.0);
        }
    }
    EXPECT_EQ(grid::rate(1.0), 1.0);
    EXPECT_EQ(grid::rate(-0.5), 0.0);
    // z' = 0.7^(3/2) is the threshold: z = 1.5·0.7^1.5 − 0.5.
    EXPECT_NEAR(grid::rate(1.5 * std::pow(0.7, 1.5) - 0.5 + 1e-9), 0.0, 1e-6);
    EXPECT_NEAR(grid::rate(1.5 * std::pow(0.85, 1.5) - 0.5), 0.5, 1e-12);
}

// The module's rates are the equations evaluated in full (cos α and sin α at each call, the cube root always taken),
// bit for bit, at random points and at z just around the threshold, where the cube root is skipped below 0.342.
TEST(GridCells, RatesAreTheEquationsBitForBit) {
    GridParams p;
    p.spacing = 4.0;
    p.n = 64;
    const GridCells module(p, 3);
    const auto full = [&](const grid::Cell& c, double x, double y) {
        const double dx = x - c.tx, dy = y - c.ty;
        const double rx = std::cos(c.orientation) * dx + std::sin(c.orientation) * dy;
        const double ry = -std::sin(c.orientation) * dx + std::cos(c.orientation) * dy;
        const double f = 2.0 * kPi / p.spacing, h = std::sqrt(3.0) / 2.0;
        const double z = (std::cos(f * rx) + std::cos(f * (rx / 2 + h * ry)) + std::cos(f * (rx / 2 - h * ry))) / 3.0;
        const double zn = std::min(std::max((z + 0.5) / 1.5, 0.0), 1.0);
        return std::min(std::max((std::cbrt(zn * zn) - 0.7) / 0.3, 0.0), 1.0);
    };
    std::mt19937_64 gen(4);
    std::uniform_real_distribution<double> u(-20, 20);
    std::vector<double> out(64);
    int firing = 0;
    for (int k = 0; k < 2000; ++k) {
        const double x = u(gen), y = u(gen);
        module.rates(x, y, out);
        for (int c = 0; c < 64; ++c) {
            ASSERT_EQ(out[c], full(module.cells()[c], x, y)) << k << " " << c;
            firing += out[c] > 0;
        }
    }
    EXPECT_GT(firing, 2000);
    // Around the threshold z' = 0.7^1.5 (the rate's 0), and across the skip's bound z'² = 0.342.
    for (double zn = std::sqrt(0.340); zn < std::sqrt(0.345); zn += 1e-6) {
        const double z = 1.5 * zn - 0.5, zq = std::min(std::max((z + 0.5) / 1.5, 0.0), 1.0);
        ASSERT_EQ(grid::rate(z), std::min(std::max((std::cbrt(zq * zq) - 0.7) / 0.3, 0.0), 1.0)) << z;
    }
}

TEST(GridCells, EachOrientationsPhasesFormANet) {
    // The first 64 Sobol points, digitally shifted, put one point in each of the 8 × 8 squares of the unit cell.
    for (std::uint64_t shift : {0ull, 0x123456789abcdefull}) {
        std::vector<int> count(64, 0);
        for (std::uint32_t k = 0; k < 64; ++k) {
            double u, v;
            grid::sobol_point(k, shift, u, v);
            ASSERT_GE(u, 0.0);
            ASSERT_LT(v, 1.0);
            ++count[static_cast<int>(u * 8) * 8 + static_cast<int>(v * 8)];
        }
        for (int c : count) EXPECT_EQ(c, 1);
    }
    // The seed moves the phases; the same seed gives the same ones.
    GridParams p;
    EXPECT_EQ(grid::module(p, 1)[5].tx, grid::module(p, 1)[5].tx);
    EXPECT_NE(grid::module(p, 1)[5].tx, grid::module(p, 2)[5].tx);
}

TEST(GridCells, PathIntegrationIsSeededAndCarriesOverBlocksAndCheckpoints) {
    GridParams pose_fed, path_fed;
    pose_fed.n = path_fed.n = 40;
    path_fed.input = GridInput::path;
    const auto steps = walk(30);

    // Without noise, path integration is the true position (to rounding).
    path_fed.path_noise = 0;
    GridCells truth(pose_fed, 3), exact(path_fed, 3);
    const auto a = run(truth, steps), b = run(exact, steps);
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_NEAR(a[i], b[i], 1e-9);

    path_fed.path_noise = 0.05;
    GridCells one(path_fed, 3), two(path_fed, 3), other(path_fed, 4);
    const auto whole = run(one, steps);
    EXPECT_NE(whole, a);
    EXPECT_NE(whole, run(other, steps));
    // In two blocks, the second restored into a fresh population from the first's state: the same bits.
    const std::vector<ModelStep> first(steps.begin(), steps.begin() + 13), rest(steps.begin() + 13, steps.end());
    auto split = run(two, first);
    GridCells resumed(path_fed, 3);
    resumed.restore(two.state());
    const auto tail = run(resumed, rest, 13);
    split.insert(split.end(), tail.begin(), tail.end());
    EXPECT_EQ(split, whole);
}

TEST(PopulationKinds, AModelsYamlListsPopulationsThatRunInATrial) {
    const auto model = config::model_from_yaml(config::YamlView::load_string(R"(
base: 2d
populations:
  - {name: grid-s, kind: grid, spacing: 4, n: 16, inputs: []}
  - {name: hd, kind: head-direction}
)",
                                                                             "model.yaml"));
    ASSERT_EQ(model.populations.size(), 2u);
    EXPECT_EQ(model.populations[0].key,
              "grid spacing=4 orientation=0 n_orientations=8 n=16 input=pose path_noise=0.01");
    TrialConfig t;
    t.world = WorldSpec{"cross", 0, "+x+y"};
    t.model = model;
    t.seed = 5;
    t.protocol.explore_hours = t.protocol.sample_hours = 0.02;
    const GroupResult r = run_trial_group({t});
    const auto& pops = r.models[0].populations;
    ASSERT_EQ(pops.size(), 2u);
    const std::size_t n = r.t.size();
    ASSERT_GT(n, 10u);
    GridParams gp;
    gp.n = 16;
    const GridCells expect(gp, 5);
    std::vector<double> g(16), h(8);
    for (std::size_t j = 0; j < n; ++j) {
        expect.rates(r.x[j], r.y[j], g);
        hd::planar_rates(r.heading[j], h);
        for (int c = 0; c < 16; ++c) ASSERT_FLOAT_EQ(pops[0].rates[j * 16 + c], static_cast<float>(g[c])) << j;
        for (int c = 0; c < 8; ++c) ASSERT_FLOAT_EQ(pops[1].rates[j * 8 + c], static_cast<float>(h[c])) << j;
    }
}

// Navigation to goals (SPEC §17, docs/navigation.md): the shortest path against hand-made grids and a brute-force
// relaxation, the HD-conditioned adjacency's update, replay and the choice of direction on a hand-made chain of
// cells, and closed-loop runs (one scale, and a small multiscale model) that reach a goal in sight, the same for the
// same seed. (The update, replay and the combination of scales against numpy: test/python/test_navigation.py.)
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "../support/temp_dir.hpp"

#include "bvc3d/agent/learning_walk.hpp"
#include "bvc3d/agent/shortest_path.hpp"
#include "bvc3d/agent/voxel_path.hpp"
#include "bvc3d/config/population_kinds.hpp"
#include "bvc3d/config/world_yaml.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/navigation.hpp"
#include "bvc3d/navigation/adjacency_kernels.hpp"
#include "bvc3d/navigation/packed_adjacency.hpp"
#include "bvc3d/navigation/replay.hpp"
#include "bvc3d/navigation/rollouts.hpp"
#include "bvc3d/navigation/scale_mix.hpp"
#include "bvc3d/navigation/sparse_adjacency.hpp"

using namespace bvc3d;

namespace {

// Distances between usable cell centres by relaxing every edge until nothing changes (Bellman-Ford): shares
// nothing with A* but the move rules (8 neighbours, a diagonal only when both cells beside it are usable).
std::vector<double> brute_force(const std::vector<char>& ok, int nx, int ny, int from, double h) {
    std::vector<double> d(ok.size(), std::numeric_limits<double>::infinity());
    d[std::size_t(from)] = 0;
    const auto usable = [&](int x, int y) {
        return x >= 0 && y >= 0 && x < nx && y < ny && ok[std::size_t(y * nx + x)];
    };
    for (bool changed = true; changed;) {
        changed = false;
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) {
                if (!usable(x, y)) continue;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        if ((dx == 0 && dy == 0) || !usable(x + dx, y + dy)) continue;
                        if (dx != 0 && dy != 0 && !(usable(x + dx, y) && usable(x, y + dy))) continue;
                        const double via = d[std::size_t((y + dy) * nx + x + dx)] + h * std::hypot(dx, dy);
                        if (via < d[std::size_t(y * nx + x)] - 1e-12) d[std::size_t(y * nx + x)] = via, changed = true;
                    }
            }
    }
    return d;
}

FreeSpaceGrid grid_of(const std::vector<char>& ok, int nx, int ny, double h) {
    std::vector<float> rooms(ok.size());
    for (std::size_t i = 0; i < ok.size(); ++i) rooms[i] = ok[i] ? 1.0f : 0.0f;
    return FreeSpaceGrid(Vec2(0, 0), h, nx, ny, rooms);
}

}  // namespace

TEST(ShortestPath, GoesAroundAHandMadeWall) {
    // 12 × 7 cells of 1 m; a wall at column 5 from row 0 to row 4: from (0, 0) to (11, 0) the path climbs to row 5.
    const int nx = 12, ny = 7;
    std::vector<char> ok(nx * ny, 1);
    for (int y = 0; y <= 4; ++y) ok[std::size_t(y * nx + 5)] = 0;
    const auto grid = grid_of(ok, nx, ny, 1.0);
    const auto path = shortest_path(grid, {0.5, 0.5}, {11.5, 0.5}, 0.5);
    ASSERT_TRUE(path.found);
    // By hand: (0,0) → (4,5) is 4 diagonals and 1 straight; (4,5) → (6,5) straight (the corner rule forbids cutting
    // past the wall's top end); (6,5) → (11,0) 5 diagonals: 9√2 + 3.
    const auto d = brute_force(ok, nx, ny, 0, 1.0);
    EXPECT_NEAR(path.length, d[11], 1e-9);
    EXPECT_NEAR(path.length, 9 * std::sqrt(2.0) + 3, 1e-9);
    for (const Vec2& p : path.points) EXPECT_FALSE(p.x() > 5 && p.x() < 6 && p.y() < 5) << p.transpose();
}

TEST(ShortestPath, MatchesBruteForceOnRandomGrids) {
    std::mt19937 gen(7);
    for (int trial = 0; trial < 20; ++trial) {
        const int nx = 9 + trial % 5, ny = 8 + trial % 3;
        std::vector<char> ok(std::size_t(nx * ny));
        for (auto& c : ok) c = gen() % 100 >= 30;
        ok[0] = 1;
        const auto grid = grid_of(ok, nx, ny, 0.1);
        const auto d = brute_force(ok, nx, ny, 0, 0.1);
        for (int to = 0; to < nx * ny; ++to) {
            if (!ok[std::size_t(to)]) continue;
            const Vec2 b = grid.center(grid.cell_at(std::size_t(to)));
            const auto path = shortest_path(grid, grid.center({0, 0}), b, 0.5);
            ASSERT_EQ(path.found, std::isfinite(d[std::size_t(to)])) << trial << " " << to;
            if (path.found) {
                EXPECT_NEAR(path.length, d[std::size_t(to)], 1e-9) << trial << " " << to;
            }
        }
    }
}

TEST(ShortestPath, JoinsEndsOutsideUsableCellsAndRefusesUnreachable) {
    const int nx = 10, ny = 3;
    std::vector<char> ok(nx * ny, 1);
    ok[std::size_t(1 * nx + 0)] = 0;  // (0, 1) unusable: a point there is joined to its nearest usable cell
    const auto grid = grid_of(ok, nx, ny, 1.0);
    const auto path = shortest_path(grid, {0.5, 1.4}, {9.5, 1.5}, 0.5);
    ASSERT_TRUE(path.found);
    // Nearest usable centre to (0.5, 1.4) is (0.5, 0.5) (0.9 away; (1.5, 1.5) is 1.005 away), then the grid.
    const auto d = brute_force(ok, nx, ny, 0, 1.0);
    EXPECT_NEAR(path.length, 0.9 + d[std::size_t(1 * nx + 9)], 1e-9);
    for (int y = 0; y < ny; ++y) ok[std::size_t(y * nx + 5)] = 0;  // a wall across: no path
    EXPECT_FALSE(shortest_path(grid_of(ok, nx, ny, 1.0), {0.5, 0.5}, {9.5, 0.5}, 0.5).found);
    EXPECT_FALSE(shortest_path(grid, {-3, 0.5}, {9.5, 0.5}, 0.5).found);  // outside the grid
}

TEST(HdAdjacency, UpdateIsAntisymmetricSkipsBumpsAndDecays) {
    AdjacencyParams p;
    HdAdjacency adj(3, p);
    // Cell 0 then cell 1 fire while heading east (HD cell 0 fully on).
    const auto east = hd_rates(0.0);
    adj.learn(std::vector<double>{1, 0, 0}, east, false);
    adj.learn(std::vector<double>{0, 1, 0}, east, false);
    EXPECT_GT(adj.weight(0, 1, 0), 0);  // 1 follows 0 heading east
    for (int k = 0; k < 8; ++k)
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) EXPECT_FLOAT_EQ(adj.weight(k, i, j), -adj.weight(k, j, i));
    EXPECT_LT(adj.weight(4, 1, 0), 0);  // heading west the same sequence runs backwards
    const double before = adj.weight(0, 1, 0);
    adj.learn(std::vector<double>{0, 0, 1}, east, true);  // a bump: no update, only the decay
    EXPECT_NEAR(adj.weight(0, 1, 0), before * (1 - p.decay), 1e-7 * before);
    EXPECT_EQ(adj.weight(0, 2, 1), 0.0);
}

// The sparse copy navigation multiplies with: prune 0 gives exactly the dense products' bits (both of apply's forms:
// few active cells, many); a prune leaves out the weights at most that fraction of their matrix's largest, and the
// products are those of the matrices with them set to 0 (summed here another way).
TEST(HdAdjacency, SparseCopyIsExactAtPruneZeroAndDropsOnlySmallWeights) {
    const int n = 40;
    HdAdjacency adj(n);
    std::mt19937 gen(7);
    std::uniform_real_distribution<double> u(0, 1);
    for (int t = 0; t < 300; ++t) {
        std::vector<double> v(n, 0.0);
        for (int c = 0; c < 3; ++c) v[std::size_t((t / 4 + c * 7) % n)] = u(gen);
        adj.learn(v, hd_rates(6.3 * u(gen)), t % 11 == 0);
    }
    const SparseAdjacency exact(adj, 0.0), pruned(adj, 0.05);
    EXPECT_LT(pruned.entries(), exact.entries());
    for (int active : {3, 30}) {
        std::vector<double> x(n, 0.0);
        for (int c = 0; c < active; ++c) x[std::size_t((c * 13) % n)] = u(gen);
        std::vector<double> dense(n), a(n), b(n);
        for (int k = 0; k < adj.n_hd(); ++k) {
            adj.apply(k, x, dense);
            exact.apply(k, x, a);
            pruned.apply(k, x, b);
            double top = 0;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) top = std::max(top, std::abs(adj.weight(k, i, j)));
            for (int i = 0; i < n; ++i) {
                EXPECT_EQ(a[std::size_t(i)], dense[std::size_t(i)]) << "k " << k << " i " << i;
                double kept = 0;
                for (int j = 0; j < n; ++j)
                    if (std::abs(adj.weight(k, i, j)) > 0.05 * top) kept += adj.weight(k, i, j) * x[std::size_t(j)];
                EXPECT_NEAR(b[std::size_t(i)], kept, 1e-6 * top) << "k " << k << " i " << i;
            }
        }
    }
}

// A pruned copy's products with a dense state (kernels::row_sums16): entry o of a row goes to lane o mod 16, each lane
// sums in order, lanes l and l + 8 are added, then the eight in pairs — restated here lane by lane, and the bits must
// match on whatever instruction set runs the test (scripts/check-dispatch compares the baseline build's navigation).
// Rows of every length 0–70 (whole blocks of 16 and every tail), against long double sums too.
TEST(HdAdjacency, PrunedRowSumsAddSixteenLanesInAFixedOrder) {
    std::mt19937 gen(3);
    std::uniform_real_distribution<double> u(-1, 1);
    const int n = 300, rows = 71;
    std::vector<std::uint32_t> start{0};
    std::vector<std::uint16_t> col;
    std::vector<float> w;
    for (int i = 0; i < rows; ++i) {
        const std::size_t end = col.size() + std::size_t(i);  // row i has i entries, at ascending columns
        for (int j = 0; j < n && col.size() < end; j += 1 + int(gen() % 7))
            col.push_back(std::uint16_t(j)), w.push_back(float(u(gen)));
        start.push_back(std::uint32_t(col.size()));
    }
    std::vector<double> x(n), out(rows);
    for (double& v : x) v = u(gen);
    const double scale = 0.37;
    kernels::row_sums16(start.data(), col.data(), w.data(), rows, x.data(), scale, out.data());
    for (int i = 0; i < rows; ++i) {
        double lane[16] = {};
        long double exact = 0;
        for (std::uint32_t e = start[std::size_t(i)]; e < start[std::size_t(i) + 1]; ++e) {
            lane[(e - start[std::size_t(i)]) % 16] += double(w[e]) * x[col[e]];
            exact += static_cast<long double>(w[e]) * x[col[e]];
        }
        double half[8];
        for (int l = 0; l < 8; ++l) half[l] = lane[l] + lane[l + 8];
        const double sum = ((half[0] + half[1]) + (half[2] + half[3])) + ((half[4] + half[5]) + (half[6] + half[7]));
        EXPECT_EQ(out[std::size_t(i)], scale * sum) << "row " << i;
        EXPECT_NEAR(out[std::size_t(i)], double(scale * exact), 1e-14) << "row " << i;
    }
}

namespace {

// A random binary16 with its value decoded here by its definition, ±2^(E−15)·(1 + m/2¹⁰) (E = 0: ±2⁻¹⁴·m/2¹⁰).
std::pair<std::uint16_t, double> random_half(std::mt19937& gen) {
    const unsigned sign = gen() % 2, exponent = gen() % 17, mantissa = gen() % 1024;  // exponents up to 2¹
    const double value =
        exponent == 0 ? std::ldexp(double(mantissa), -24) : std::ldexp(1.0 + mantissa / 1024.0, int(exponent) - 15);
    return {std::uint16_t(sign << 15 | exponent << 10 | mantissa), sign ? -value : value};
}

}  // namespace

// The packed copy's products (kernels::half_rows, half_columns), restated: rows — entry o of a row into accumulator
// o mod 4 (float32), (a0 + a1) + (a2 + a3), × f_k; columns — 0 minus each entry's product, rows j in order, skipping
// rows whose state is 0 in every direction, × f_k. Bits must match on whatever instruction set runs the test (8
// directions: AVX2 where the CPU has it; 3: one at a time), whatever the tiles (blocks of rows, panels of columns:
// one tile, rows cut mid-way by panels with every phase mod 4, a short last block, single rows and columns), and the
// sums lie within float32's rounding of the exact.
TEST(PackedAdjacency, KernelsAddInAFixedOrder) {
    std::mt19937 gen(5);
    std::uniform_real_distribution<float> u(-1, 1);
    for (int K : {8, 3}) {
        const int n = 90;
        std::vector<std::uint32_t> start{0};
        std::vector<std::uint16_t> col, h;
        std::vector<double> value;
        for (int i = 0; i < n; ++i) {
            for (int j = 0; j < n; j += 1 + int(gen() % (1 + unsigned(i) % 9))) {
                col.push_back(std::uint16_t(j));
                for (int k = 0; k < K; ++k) {
                    const auto [bits, v] = random_half(gen);
                    h.push_back(bits), value.push_back(v);
                }
            }
            start.push_back(std::uint32_t(col.size()));
        }
        std::vector<float> x(std::size_t(n * K)), f(static_cast<std::size_t>(K)), y(x.size()), yc(x.size());
        for (float& v : x) v = u(gen);
        for (int j = 0; j < n; j += 3) std::fill_n(&x[std::size_t(j * K)], K, 0.0f);  // rows the columns form skips
        for (float& v : f) v = u(gen);
        struct Tiling {
            int block, panel;
        };
        for (const Tiling tiling : {Tiling{64, 512}, Tiling{7, 16}, Tiling{13, 29}, Tiling{1, 1}, Tiling{64, 89}}) {
            const kernels::HalfTiles tiles(start.data(), col.data(), h.data(), n, K, tiling.block, tiling.panel);
            ASSERT_EQ(tiles.col.size(), col.size());
            kernels::half_rows(tiles, x.data(), f.data(), y.data());
            kernels::half_columns(tiles, x.data(), f.data(), yc.data());
            std::vector<float> columns(x.size(), 0.0f);
            for (int j = 0; j < n; ++j) {
                bool zero = true;
                for (int k = 0; k < K; ++k) zero = zero && x[std::size_t(j * K + k)] == 0.0f;
                if (zero) continue;
                for (std::uint32_t e = start[std::size_t(j)]; e < start[std::size_t(j) + 1]; ++e)
                    for (int k = 0; k < K; ++k)
                        columns[std::size_t(col[e] * K + k)] -=
                            float(value[e * std::size_t(K) + std::size_t(k)]) * x[std::size_t(j * K + k)];
            }
            for (int i = 0; i < n; ++i)
                for (int k = 0; k < K; ++k) {
                    float a[4] = {};
                    long double exact = 0, size = 0;
                    for (std::uint32_t e = start[std::size_t(i)]; e < start[std::size_t(i) + 1]; ++e) {
                        const double w = value[e * std::size_t(K) + std::size_t(k)];
                        const float xv = x[std::size_t(col[e] * K + k)];
                        a[(e - start[std::size_t(i)]) % 4] += float(w) * xv;
                        exact += static_cast<long double>(w) * xv, size += std::abs(static_cast<long double>(w) * xv);
                    }
                    const auto at = std::size_t(i * K + k);
                    EXPECT_EQ(y[at], f[std::size_t(k)] * ((a[0] + a[1]) + (a[2] + a[3]))) << "K " << K << " row " << i;
                    EXPECT_NEAR(y[at], double(f[std::size_t(k)] * exact), double(1e-6L * size))
                        << "K " << K << " row " << i;
                    EXPECT_EQ(yc[at], f[std::size_t(k)] * columns[at]) << "K " << K << " column " << i;
                }
        }
    }
    const std::uint32_t start[] = {0, 1};
    const std::uint16_t col[] = {1}, h[] = {0};
    EXPECT_THROW(kernels::HalfTiles(start, col, h, 1, 1), std::invalid_argument);  // column 1 of 1 row
    EXPECT_THROW(kernels::HalfTiles(start, col, h, 2, 1, 65, 512), std::invalid_argument);
    const std::uint32_t pair_start[] = {0, 2, 2};
    const std::uint16_t twice[] = {1, 1}, pair_h[] = {0, 0};
    EXPECT_THROW(kernels::HalfTiles(pair_start, twice, pair_h, 2, 1), std::invalid_argument);  // not ascending
}

// The packed copy keeps an entry where any direction keeps it (|w| > prune·max|W_rec[k]|, counted here), holds each
// direction's kept weights within 2⁻¹¹ of themselves (0 where that direction leaves the entry out), and its products
// — by columns with few active cells, by rows with many — lie within that of the kept weights' products. 8
// directions (AVX2 where the CPU has it) and 3.
TEST(PackedAdjacency, KeepsTheUnionOfThePatternsAndEachWeightToSixteenBits) {
    const int n = 40;
    std::mt19937 gen(7);
    std::uniform_real_distribution<double> u(0, 1);
    for (int n_hd : {8, 3}) {
        AdjacencyParams params;
        params.n_hd = n_hd;
        HdAdjacency adj(n, params);
        for (int t = 0; t < 300; ++t) {
            std::vector<double> v(n, 0.0);
            for (int c = 0; c < 3; ++c) v[std::size_t((t / 4 + c * 7) % n)] = u(gen);
            adj.learn(v, hd_rates(6.3 * u(gen), n_hd), t % 11 == 0);
        }
        const double prune = 0.05;
        const PackedAdjacency packed(adj, prune);
        std::vector<double> top(std::size_t(n_hd), 0.0);
        for (int k = 0; k < n_hd; ++k)
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j)
                    top[std::size_t(k)] = std::max(top[std::size_t(k)], std::abs(adj.weight(k, i, j)));
        const auto kept = [&](int k, int i, int j) {
            return std::abs(adj.weight(k, i, j)) > prune * top[std::size_t(k)] * (1 + 1e-6);
        };
        std::size_t one_most = 0, all = 0;
        for (int k = 0; k < n_hd; ++k) {
            std::size_t count = 0;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) count += kept(k, i, j);
            one_most = std::max(one_most, count);
        }
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                bool any = false;
                for (int k = 0; k < n_hd; ++k) any = any || kept(k, i, j);
                all += any;
            }
        EXPECT_EQ(packed.entries(), all) << n_hd;
        EXPECT_GT(packed.entries(), one_most) << n_hd;
        for (int active : {3, 30}) {
            std::vector<float> x(std::size_t(n * n_hd), 0.0f), y(x.size());
            for (int c = 0; c < active; ++c)
                for (int k = 0; k < n_hd; ++k) x[std::size_t(((c * 13) % n) * n_hd + k)] = float(u(gen));
            packed.apply(x, y);
            for (int k = 0; k < n_hd; ++k)
                for (int i = 0; i < n; ++i) {
                    double sum = 0, size = 0;
                    for (int j = 0; j < n; ++j) {
                        const double xj = x[std::size_t(j * n_hd + k)];
                        if (kept(k, i, j)) sum += adj.weight(k, i, j) * xj, size += std::abs(adj.weight(k, i, j) * xj);
                    }
                    EXPECT_NEAR(y[std::size_t(i * n_hd + k)], sum, std::ldexp(size, -11) + 1e-6 * top[std::size_t(k)])
                        << "n_hd " << n_hd << " active " << active << " k " << k << " i " << i;
                }
        }
    }
}

namespace {

// A chain of n cells along x: heading east (HD 0) cell i+1 follows cell i, heading west (HD 4) the reverse.
HdAdjacency chain(int n) {
    HdAdjacency adj(n);
    std::vector<float> w(std::size_t(8 * n * n), 0.0f);
    const auto at = [&](int k, int i, int j) -> float& { return w[std::size_t((k * n + i) * n + j)]; };
    for (int i = 0; i + 1 < n; ++i) {
        at(0, i + 1, i) = 1, at(0, i, i + 1) = -1;
        at(4, i, i + 1) = 1, at(4, i + 1, i) = -1;
    }
    adj.set_weights(w);
    return adj;
}

}  // namespace

TEST(RewardCells, ReplayValueFallsAlongTheChainAndTheChoiceHeadsToTheGoal) {
    // Replay spreads from the goal's cell through every direction's links, so value falls with the distance from
    // the goal (near the chain's far end it rises a little again: an end cell has no successor to inhibit it,
    // as the formula says; the exact values are checked against numpy in test/python/test_navigation.py).
    const int n = 30;
    const auto adj = chain(n);
    RewardParams p;
    const auto w = replay(adj, n - 1, p);
    for (int i = n - 12; i + 1 < n; ++i) EXPECT_LT(w[std::size_t(i)], w[std::size_t(i + 1)]) << i;
    EXPECT_GT(w[0], 0.0);
    std::vector<double> v(n, 0.0);
    v[20] = 1.0;
    const auto returns = direction_returns(adj, w, v, p);
    for (int k = 1; k < 8; ++k) EXPECT_GT(returns[0], returns[std::size_t(k)]) << k;  // east, toward the goal
    const auto prob = softmax(returns, p.beta, std::vector<char>(8, 1));
    EXPECT_GT(prob[0], 0.99);
    auto closed = std::vector<char>(8, 1);
    closed[0] = 0;  // east blocked: never chosen
    EXPECT_EQ(softmax(returns, p.beta, closed)[0], 0.0);
    // Only the offered directions rolled out: their returns bit for bit, 0 for the others.
    const SparseAdjacency copy(adj);
    const auto offered = direction_returns(copy, w, v, p, closed);
    for (int k = 0; k < 8; ++k) EXPECT_EQ(offered[std::size_t(k)], k == 0 ? 0.0 : returns[std::size_t(k)]) << k;
    EXPECT_THROW(direction_returns(copy, w, v, p, std::vector<char>(3, 1)), InputError);
    // The packed copy: the chain's weights (±1) are 16-bit floats, so only its float32 states differ from the above.
    const PackedAdjacency packed(adj, 0.0);
    const auto half = direction_returns(packed, w, v, p);
    for (int k = 0; k < 8; ++k) EXPECT_NEAR(half[std::size_t(k)], returns[std::size_t(k)], 1e-6) << k;
    const auto half_offered = direction_returns(packed, w, v, p, closed);
    for (int k = 0; k < 8; ++k) EXPECT_EQ(half_offered[std::size_t(k)], k == 0 ? 0.0 : half[std::size_t(k)]) << k;
    EXPECT_THROW(direction_returns(packed, w, v, p, std::vector<char>(3, 1)), InputError);
    // The goal at the chain's start: west wins.
    v.assign(n, 0.0);
    v[9] = 1.0;
    const auto back = direction_returns(adj, replay(adj, 0, p), v, p);
    for (int k = 0; k < 8; ++k) {
        if (k != 4) {
            EXPECT_GT(back[4], back[std::size_t(k)]) << k;
        }
    }
    EXPECT_DOUBLE_EQ(reward(w, v), w[9]);
}

namespace {

// A navigation run as these tests describe it, and its record split into starts.
struct NavigationSetup {
    ModelSpec model = model_preset("2d");
    std::vector<NavigationGoal> goals;
    NavigationParams nav;
    AdjacencyParams adjacency;
    RewardParams reward;
    NavigationSpec spec() const {
        NavigationSpec s;
        s.space.goals = goals;
        s.space.nav = nav;
        s.space.n_hd = adjacency.n_hd;
        s.adjacency = adjacency;
        s.reward = reward;
        return s;
    }
};

struct RunStart {
    Vec3 start = Vec3::Zero();
    bool success = false;
    double path_m = 0, shortest_m = 0;
    std::vector<Vec3> path;
};

struct NavigationRun {
    std::vector<int> goal_cells, visits;
    double coverage = 0;
    std::vector<RunStart> starts;
    std::vector<double> map_reward;
};

NavigationRun navigate(const World& world, const NavigationSetup& setup, std::uint64_t seed) {
    const NavigationRecord r = bvc3d::navigate(world, setup.model, setup.spec(), seed);
    NavigationRun run{r.goal_cells, r.visits, r.coverage, {}, r.map_reward};
    const auto d = std::size_t(r.dims);
    const auto point = [&](const std::vector<double>& v, std::size_t i) {
        Vec3 p = Vec3::Zero();
        for (std::size_t k = 0; k < d; ++k) p[Eigen::Index(k)] = v[i * d + k];
        return p;
    };
    for (std::size_t i = 0; i < r.n_starts(); ++i) {
        RunStart s{point(r.start, i), r.success[i] != 0, r.path_m[i], r.shortest_m[i], {}};
        for (auto k = r.path_start[i]; k < r.path_start[i + 1]; ++k) s.path.push_back(point(r.path, k));
        run.starts.push_back(std::move(s));
    }
    return run;
}

void check_goals(const World& world, const NavigationSetup& setup) { bvc3d::check_goals(world, setup.spec()); }

void check_model(const ModelSpec& model, const NavigationSetup& setup) {
    navigation_trial(WorldSpec::built("test"), model, std::make_shared<NavigationSpec>(setup.spec()), 0);
}

}  // namespace

namespace {

World open_room(const std::filesystem::path& dir) {
    const auto file = dir / "room.yaml";
    std::ofstream(file) << "name: room\nobjects:\n"
                           "  - box: {center: [0, 0, -0.05], size: [8, 8, 0.1]}\n"
                           "  - box: {center: [0, 0, 2.55], size: [8, 8, 0.1]}\n"
                           "  - box: {center: [-4.1, 0, 1.25], size: [0.2, 8.4, 2.5]}\n"
                           "  - box: {center: [4.1, 0, 1.25], size: [0.2, 8.4, 2.5]}\n"
                           "  - box: {center: [0, -4.1, 1.25], size: [8.4, 0.2, 2.5]}\n"
                           "  - box: {center: [0, 4.1, 1.25], size: [8.4, 0.2, 2.5]}\n"
                           "  - box: {center: [1, -1, 1.25], size: [0.6, 0.6, 2.5]}\n"
                           "walkable: {rect: [-4, -4, 4, 4]}\nstart: {rect: [-3.5, -3.5, 3.5, 3.5]}\n";
    return World(config::load_world_file(file.string()));
}

NavigationSetup room_setup() {
    NavigationSetup s;
    s.model = model_preset("2d");
    s.goals = {{2.5, 2.5}};
    s.nav.max_learn_hours = 0.5;
    s.nav.goal_visits = 3;
    s.nav.coverage = 0.9;
    s.nav.starts = 4;
    s.nav.min_start_distance = 4.0;
    return s;
}

}  // namespace

TEST(Navigation, ReachesAGoalInSightInAnOpenRoomTheSameForTheSameSeed) {
    test::TempDir dir;
    const World world = open_room(dir.path());
    const auto setup = room_setup();
    const auto run = navigate(world, setup, 3);
    ASSERT_GE(run.goal_cells[0], 0);
    EXPECT_GE(run.visits[0], 1);
    int reached = 0;
    for (const auto& s : run.starts) {
        reached += s.success;
        EXPECT_GT(s.shortest_m, 4.0 - 1e-9);
        if (s.success) {
            EXPECT_LE((s.path.back() - setup.goals[0].p).norm(), setup.nav.success_radius + 1e-9);
            EXPECT_LT(s.path_m / s.shortest_m, 2.5);  // a blind walk (β = 0) fails all four at 10×
        }
    }
    EXPECT_GE(reached, 3) << "of " << run.starts.size();
    const auto again = navigate(world, setup, 3);
    ASSERT_EQ(again.starts.size(), run.starts.size());
    for (std::size_t i = 0; i < run.starts.size(); ++i) {
        EXPECT_EQ(again.starts[i].path_m, run.starts[i].path_m);
        EXPECT_EQ(again.starts[i].path.size(), run.starts[i].path.size());
        EXPECT_EQ(again.starts[i].start, run.starts[i].start);
    }
    EXPECT_EQ(again.map_reward, run.map_reward);
    EXPECT_EQ(again.goal_cells, run.goal_cells);
}

namespace {

// A small multiscale model (SPEC §16's structure at a test's size): the paper's 2-D model as the first scale, and a
// second scale of broader BVCs and 150 place cells fed by them and a grid module.
ModelSpec two_scales() {
    ModelSpec m = model_preset("2d");
    m.name = "two-scales";
    BvcParams bvc = m.bvc;
    bvc.n_per_axis = 60;
    bvc.sigma_r = 1.0;
    bvc.sigma_theta = 3 * pi / 180;
    GridParams grid;
    grid.spacing = 5.5;
    grid.n = 100;
    PlaceParams place;
    place.n_place = 150;
    place.grid_influence = 0.35;
    place.gamma_pp = 0.7;
    m.populations = {config::grid_spec("grid-m", grid), config::bvc_layer_spec("bvc-m", bvc),
                     config::grid_place_spec("place-m", place, {"bvc-m", "grid-m"})};
    return m;
}

// A run of `setup` that reaches at least 3 of its 4 starts by paths under 2.5 × the shortest, and again the same paths.
NavigationRun reaches_in_sight_twice_alike(const World& world, const NavigationSetup& setup) {
    auto run = navigate(world, setup, 3);
    int reached = 0;
    for (const auto& s : run.starts) {
        reached += s.success;
        if (s.success) {
            EXPECT_LT(s.path_m / s.shortest_m, 2.5);
        }
    }
    EXPECT_GE(reached, 3) << "of " << run.starts.size();
    const auto again = navigate(world, setup, 3);
    EXPECT_EQ(again.starts.size(), run.starts.size());
    for (std::size_t i = 0; i < std::min(run.starts.size(), again.starts.size()); ++i)
        EXPECT_EQ(again.starts[i].path, run.starts[i].path) << i;
    return run;
}

}  // namespace

TEST(Navigation, MultiscaleReachesAGoalInSightTheSameForTheSameSeed) {
    test::TempDir dir;
    const World world = open_room(dir.path());
    auto setup = room_setup();
    setup.model = two_scales();
    ASSERT_EQ(setup.model.place_scales(), (std::vector<std::string>{"place", "place-m"}));
    const auto run = reaches_in_sight_twice_alike(world, setup);
    // The second scale takes part in the choice: the first alone (the 2-D model, the same learning walk and the
    // same first scale's reward cell) walks other paths.
    auto single = room_setup();
    const auto alone = navigate(world, single, 3);
    ASSERT_EQ(run.goal_cells.size(), 2u);  // a reward cell per scale
    EXPECT_EQ(alone.goal_cells.front(), run.goal_cells.front());
    bool differs = false;
    for (std::size_t i = 0; i < run.starts.size(); ++i) differs = differs || alone.starts[i].path != run.starts[i].path;
    EXPECT_TRUE(differs);
    // A second scale without a λ of its own: refused, naming the key.
    setup.reward.scale_lambdas = {};
    try {
        navigate(world, setup, 3);
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("scale_lambdas"), std::string::npos) << e.what();
    }
}

// `adjacency: {prune: 0.01, rollout_weights: float16}`: the rollouts read the packed copy; navigation still reaches a
// goal in sight, the same for a seed.
TEST(Navigation, ReachesAGoalInSightWithSixteenBitRolloutWeights) {
    test::TempDir dir;
    const World world = open_room(dir.path());
    auto setup = room_setup();
    setup.adjacency.prune = 0.01;
    setup.adjacency.rollout_weights = RolloutWeights::float16;
    reaches_in_sight_twice_alike(world, setup);
}

TEST(Navigation, RefusesGoalsOutsideInWallsOrNone) {
    test::TempDir dir;
    const World world = open_room(dir.path());
    auto setup = room_setup();
    setup.goals = {{2.5, 2.5}, {9, 0}};
    try {
        check_goals(world, setup);
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("goal 2 (9, 0)"), std::string::npos) << e.what();
    }
    setup.goals = {{1, -1}};
    EXPECT_THROW(check_goals(world, setup), InputError);
    setup.goals = {};
    EXPECT_THROW(check_goals(world, setup), InputError);
}

TEST(VoxelPath, MatchesBruteForceAndGoesRoundASlab) {
    // 3-D relaxation (Bellman-Ford) with the same move rule: the box of a move must be free.
    std::mt19937 gen(3);
    for (int trial = 0; trial < 6; ++trial) {
        VoxelGrid3 g{6, 5, 4, 0.5, {}};
        g.free.resize(6 * 5 * 4);
        for (auto& c : g.free) c = gen() % 100 >= 25;
        g.free[0] = 1;
        std::vector<double> d(g.free.size(), std::numeric_limits<double>::infinity());
        d[0] = 0;
        for (bool changed = true; changed;) {
            changed = false;
            for (int z = 0; z < g.nz; ++z)
                for (int y = 0; y < g.ny; ++y)
                    for (int x = 0; x < g.nx; ++x)
                        for (int dz = -1; dz <= 1; ++dz)
                            for (int dy = -1; dy <= 1; ++dy)
                                for (int dx = -1; dx <= 1; ++dx) {
                                    if ((dx | dy | dz) == 0 || !g.usable(x, y, z)) continue;
                                    bool ok = true;
                                    for (int ez = std::min(0, dz); ez <= std::max(0, dz); ++ez)
                                        for (int ey = std::min(0, dy); ey <= std::max(0, dy); ++ey)
                                            for (int ex = std::min(0, dx); ex <= std::max(0, dx); ++ex)
                                                ok = ok && g.usable(x + ex, y + ey, z + ez);
                                    if (!ok) continue;
                                    const double via = d[g.index(x + dx, y + dy, z + dz)] +
                                                       0.5 * std::sqrt(double(dx * dx + dy * dy + dz * dz));
                                    if (via < d[g.index(x, y, z)] - 1e-12) d[g.index(x, y, z)] = via, changed = true;
                                }
        }
        for (int z = 0; z < g.nz; ++z)
            for (int y = 0; y < g.ny; ++y)
                for (int x = 0; x < g.nx; ++x) {
                    if (!g.usable(x, y, z)) continue;
                    const auto p = voxel_shortest_path(g, {0, 0, 0}, {x, y, z});
                    ASSERT_EQ(p.has_value(), std::isfinite(d[g.index(x, y, z)])) << trial;
                    if (p) {
                        EXPECT_NEAR(*p, d[g.index(x, y, z)], 1e-9) << trial;
                    }
                }
    }
    // A floor-to-ceiling slab at x = 2 with one hole at the top (z = 3): up, through, down.
    VoxelGrid3 g{5, 1, 4, 1.0, std::vector<char>(20, 1)};
    for (int z = 0; z < 3; ++z) g.free[g.index(2, 0, z)] = 0;
    // (0,0,0) → (1,0,3)? The box rule forbids diagonals past the slab's edge: (0,0,0)→(1,0,1)→(1,0,2)→(1,0,3)
    // →(2,0,3)→(3,0,3)→(3,0,2)→(3,0,1)→(4,0,0): √2 + 1 + 1 + 1 + 1 + 1 + 1 + √2 = 6 + 2√2.
    EXPECT_NEAR(*voxel_shortest_path(g, {0, 0, 0}, {4, 0, 0}), 6 + 2 * std::sqrt(2.0), 1e-9);
    g.free[g.index(2, 0, 3)] = 0;
    EXPECT_FALSE(voxel_shortest_path(g, {0, 0, 0}, {4, 0, 0}).has_value());
}

namespace {

// A 6 × 6 × 3 m room whose walls, floor and ceiling bound its flight volume exactly, with a box floating at
// `box_center` of `box_size` (none if its size is 0) and, if `divided`, a floor-to-ceiling wall across it at x = 1.9.
World flight_box(const std::filesystem::path& dir, const Vec3& box_center, const Vec3& box_size, bool divided = false) {
    const auto file = dir / "flight-box.yaml";
    std::ofstream out(file);
    out << "name: flight-box\nobjects:\n"
           "  - box: {center: [0, 0, -0.05], size: [6, 6, 0.1]}\n"
           "  - box: {center: [0, 0, 3.05], size: [6, 6, 0.1]}\n"
           "  - box: {center: [-3.1, 0, 1.5], size: [0.2, 6.4, 3]}\n"
           "  - box: {center: [3.1, 0, 1.5], size: [0.2, 6.4, 3]}\n"
           "  - box: {center: [0, -3.1, 1.5], size: [6.4, 0.2, 3]}\n"
           "  - box: {center: [0, 3.1, 1.5], size: [6.4, 0.2, 3]}\n";
    if (box_size.minCoeff() > 0)
        out << "  - box: {center: [" << box_center.x() << ", " << box_center.y() << ", " << box_center.z()
            << "], size: [" << box_size.x() << ", " << box_size.y() << ", " << box_size.z() << "]}\n";
    if (divided) out << "  - box: {center: [1.9, 0, 1.5], size: [0.2, 6, 3]}\n";
    out << "flight_volume: {rect: [-3, -3, 3, 3], z_min: 0, z_max: 3}\n";
    out.close();
    return World(config::load_world_file(file.string()));
}

// Distance from p to an axis-aligned box (0 inside).
double box_distance(const Vec3& p, const Vec3& center, const Vec3& size) {
    return ((p - center).cwiseAbs() - size / 2).cwiseMax(0.0).norm();
}

}  // namespace

TEST(VoxelOccupancy, FreeVoxelsAreThoseWithHalfAMetreToTheBoxAndTheVolumesBounds) {
    test::TempDir dir;
    const Vec3 center(0.4, -0.3, 1.2), size(1.0, 0.8, 0.6);
    const World world = flight_box(dir.path(), center, size);
    const SphereCollider body(world.description(), 0.2);
    const VoxelGrid3 g = voxel_occupancy(body, 0.1, 0.5);
    // Over the box of centre positions: 5.6 × 5.6 × 2.6 m.
    ASSERT_EQ(g.nx, 56);
    ASSERT_EQ(g.ny, 56);
    ASSERT_EQ(g.nz, 26);
    std::size_t free = 0, checked = 0;
    for (std::size_t i = 0; i < g.size(); ++i) {
        const Vec3 c = g.center(g.voxel_at(i));
        // Analytic: the nearest geometry is the volume's boundary (the room's inner faces) or the box.
        const double to_bounds = std::min({3 - std::abs(c.x()), 3 - std::abs(c.y()), c.z(), 3 - c.z()});
        const double nearest = std::min(to_bounds, box_distance(c, center, size));
        if (std::abs(nearest - 0.5) < 1e-9) continue;  // on the inflated surface: either answer is right
        ++checked;
        EXPECT_EQ(bool(g.free[i]), nearest > 0.5) << c.transpose() << " nearest " << nearest;
        free += g.free[i];
    }
    EXPECT_GT(checked, g.size() * 9 / 10);
    EXPECT_GT(free, 20000u);
    // Voxels of the box itself and beside it are taken, the room's middle above it is free.
    EXPECT_FALSE(g.free[g.index(40, 25, 10)]);  // (1.25, -0.25, 1.25): 0.35 m from the box's +x face
    EXPECT_TRUE(g.free[g.index(28, 28, 22)]);   // (0.05, 0.05, 2.45)
}

TEST(VoxelOccupancy, ShortestPathGoesStraightInTheOpenAndRoundAnObstacle) {
    test::TempDir dir;
    // A box from x = -0.5 to 0.5, y = -1 to 1 and z = 1 to 2: inflated by 0.5 it fills the free height (z 0.5 to
    // 2.5) over |x| < 1, |y| < 1.5, so a path from x = -2 to x = 2 at y = 0 goes round it.
    const World world = flight_box(dir.path(), Vec3(0, 0, 1.5), Vec3(1, 2, 1));
    const SphereCollider body(world.description(), 0.2);
    const VoxelGrid3 g = voxel_occupancy(body, 0.1, 0.5);
    // In the open (y = -2.2, clear of the box's inflation): no shorter than the straight line, and no longer than
    // 26-neighbour moves make it (at most 13 % for any direction) plus half a voxel's diagonal at each end.
    const Vec3 a(-2, -2.2, 0.8), b(2, -2.2, 2.2);
    const auto open = voxel_path_between(g, a, b);
    ASSERT_TRUE(open.has_value());
    EXPECT_GE(*open, (b - a).norm() - 1e-9);
    EXPECT_LE(*open, (b - a).norm() * 1.13 + 0.1 * std::sqrt(3.0));
    // Round the box: the path crosses x = 0 at |y| >= 1.5, so it is at least 2·hypot(2, 1.5) = 5 m long.
    const auto round = voxel_path_between(g, Vec3(-2, 0, 1.5), Vec3(2, 0, 1.5));
    ASSERT_TRUE(round.has_value());
    EXPECT_GE(*round, 5.0);
    EXPECT_LE(*round, 5.0 * 1.13 + 1.0);
    // Ends inside the inflation are joined to their nearest free voxel by a straight segment, which counts.
    const auto near = voxel_path_between(g, Vec3(-0.8, 0, 1.5), Vec3(-2, 0, 1.5));
    ASSERT_TRUE(near.has_value());
    EXPECT_GE(*near, 1.2 - 1e-9);
    int parts = 0;
    voxel_parts(g, parts);
    EXPECT_EQ(parts, 1);
}

namespace {

NavigationSetup flight_setup() {
    NavigationSetup s;
    s.model = model_preset("fly-5l");
    s.goals = {{1.5, 1.5, 2.0}};
    s.nav.max_learn_hours = 0.5;
    s.nav.goal_visits = 3;
    s.nav.coverage = 0.9;
    s.nav.starts = 4;
    s.nav.reward_map_cell = 0;
    return s;
}

}  // namespace

TEST(Navigation, FlyingAgentReachesAGoalInSightInAnOpenVolumeTheSameForTheSameSeed) {
    test::TempDir dir;
    const World world = flight_box(dir.path(), Vec3::Zero(), Vec3::Zero());
    const auto setup = flight_setup();
    const auto run = navigate(world, setup, 1);
    ASSERT_GE(run.goal_cells[0], 0);
    EXPECT_GE(run.visits[0], 3);
    EXPECT_GE(run.coverage, 0.9);
    ASSERT_EQ(run.starts.size(), 4u);
    int reached = 0;
    for (const auto& s : run.starts) {
        const Vec3 goal = setup.goals[0].p;
        EXPECT_GE((s.start - goal).norm(), setup.nav.min_start_distance);
        EXPECT_GE(s.shortest_m, (s.start - goal).norm() - 1e-9);
        double length = 0, height = 0;
        for (std::size_t i = 1; i < s.path.size(); ++i) {
            EXPECT_LE((s.path[i] - s.path[i - 1]).norm(), setup.nav.step + 1e-9);
            length += (s.path[i] - s.path[i - 1]).norm();
            height = std::max(height, std::abs(s.path[i].z() - s.start.z()));
        }
        EXPECT_NEAR(length, s.path_m, 1e-9);
        reached += s.success;
        if (s.success) {
            EXPECT_LE((s.path.back() - goal).norm(), setup.nav.success_radius + 1e-9);
            EXPECT_GT(height, 0.1);                   // it flies: the goal is 2 m up, the starts elsewhere
            EXPECT_LT(s.path_m / s.shortest_m, 4.0);  // a blind flight (β = 0) fails this test (checked)
        }
    }
    EXPECT_GE(reached, 3) << "of " << run.starts.size();
    const auto again = navigate(world, setup, 1);
    ASSERT_EQ(again.starts.size(), run.starts.size());
    for (std::size_t i = 0; i < run.starts.size(); ++i) EXPECT_EQ(again.starts[i].path, run.starts[i].path) << i;
    EXPECT_EQ(again.map_reward, run.map_reward);
    EXPECT_EQ(again.goal_cells, run.goal_cells);
}

TEST(Navigation, RefusesGoalsIn3DOutsideInGeometryUnreachableOrMixed) {
    test::TempDir dir;
    const World world = flight_box(dir.path(), Vec3(0, 0, 1.5), Vec3(1, 1, 1));
    auto setup = flight_setup();
    const auto refused = [&](const World& w, std::vector<NavigationGoal> goals, const std::string& named,
                             const std::string& why) {
        setup.goals = std::move(goals);
        try {
            check_goals(w, setup);
            ADD_FAILURE() << named << " accepted";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
        }
    };
    refused(world, {{-2, -2, 1}, {0.1, 0, 2.1}}, "goal 2 (0.1, 0, 2.1)", "in or against geometry");
    refused(world, {{0.1, 0, 1.6}}, "goal 1 (0.1, 0, 1.6)", "inside a solid");
    refused(world, {{0, 0, 5}}, "goal 1 (0, 0, 5)", "outside the world's flight volume");
    refused(world, {{9, 0, 1}}, "goal 1 (9, 0, 1)", "outside the world's flight volume");
    refused(world, {{-2, -2, 1}, {2, 2}}, "goal 2 (2, 2)", "has 2 coordinates but goal 1 has 3");
    refused(world, {{2, 2}}, "goal 1 (2, 2)", "has no walkable floor");
    refused(open_room(dir.path()), {{2, 2, 1}}, "goal 1 (2, 2, 1)", "has no flight volume");
    const World divided = flight_box(dir.path(), Vec3::Zero(), Vec3::Zero(), true);
    refused(divided, {{2.5, 0, 1.5}}, "goal 1 (2.5, 0, 1.5)", "cannot be reached");
    setup.goals = {{-2, -2, 1}};
    EXPECT_NO_THROW(check_goals(divided, setup));
    // A ground model on a flying run, as a trial refuses it.
    EXPECT_THROW(check_model(model_preset("2d"), setup), InputError);
    EXPECT_NO_THROW(check_model(model_preset("fly-5l"), setup));
}

namespace {

// A learned adjacency of n cells: cells fire in a slow random sequence while the heading turns at random.
HdAdjacency learned_adjacency(int n, int n_hd, unsigned seed) {
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> u(0, 1);
    AdjacencyParams params;
    params.n_hd = n_hd;
    HdAdjacency adj(n, params);
    for (int t = 0; t < 400; ++t) {
        std::vector<double> v(std::size_t(n), 0.0);
        for (int c = 0; c < 3; ++c) v[std::size_t((t / 4 + c * 7) % n)] = u(gen);
        adj.learn(v, hd_rates(6.3 * u(gen), n_hd), t % 13 == 0);
    }
    return adj;
}

}  // namespace

// The one product interface (navigation/adjacency_product.hpp): the reference is the definition, computed here again
// from the weights (HdAdjacency::weight, the prune rule restated), and the fast copies agree with it — the float32
// sparse copy to rounding, the packed copy to its 16-bit weights.
TEST(AdjacencyProduct, BackendsAgreeWithTheReference) {
    const int n = 48;
    std::mt19937 gen(5);
    std::uniform_real_distribution<double> u(0, 1);
    for (int n_hd : {8, 3})
        for (double prune : {0.0, 0.05}) {
            const HdAdjacency adj = learned_adjacency(n, n_hd, 11);
            const ReferenceAdjacency reference(adj, prune);
            const SparseAdjacency sparse(adj, prune);
            const PackedAdjacency packed(adj, prune);
            const auto K = std::size_t(n_hd), N = std::size_t(n);
            // Every direction's own state: a dense one, then one with a few cells (the column forms).
            for (int few : {0, 1}) {
                std::vector<double> X(N * K, 0.0);
                for (std::size_t e = 0; e < X.size(); ++e)
                    if (!few || e % 11 == 0) X[e] = u(gen);
                std::vector<double> ref(N * K), fast(N * K), half(N * K);
                reference.apply(std::span<const double>(X), std::span<double>(ref));
                sparse.apply(std::span<const double>(X), std::span<double>(fast));
                packed.apply(std::span<const double>(X), std::span<double>(half));
                std::vector<double> top(K, 0.0);
                for (std::size_t k = 0; k < K; ++k)
                    for (int i = 0; i < n; ++i)
                        for (int j = 0; j < n; ++j) top[k] = std::max(top[k], std::abs(adj.weight(int(k), i, j)));
                for (std::size_t k = 0; k < K; ++k)
                    for (std::size_t i = 0; i < N; ++i) {
                        double sum = 0.0, mass = 0.0, edge = 0.0;  // edge: weights within rounding of the cut
                        for (std::size_t j = 0; j < N; ++j) {
                            const double w = adj.weight(int(k), int(i), int(j));
                            const double cut = prune * top[k];
                            if (std::abs(std::abs(w) - cut) <= 1e-6 * top[k]) edge += std::abs(w * X[j * K + k]);
                            else if (std::abs(w) > cut) sum += w * X[j * K + k];
                            mass += std::abs(w * X[j * K + k]);
                        }
                        const double at = ref[i * K + k];
                        EXPECT_NEAR(at, sum, 1e-12 * mass + edge) << n_hd << " " << prune << " " << k << " " << i;
                        // With few cells the copies take Wᵀ·x = −W·x (by columns): the learned W is antisymmetric to
                        // the rounding of its float32 updates, so that form is within float32's rounding of W·x.
                        EXPECT_NEAR(fast[i * K + k], at, (few ? 1e-6 : 1e-12) * mass)
                            << n_hd << " " << prune << " " << k << " " << i;
                        // binary16: each kept weight within 2⁻¹¹ of the largest; float32 sums.
                        EXPECT_NEAR(half[i * K + k], at, std::ldexp(1.0, -11) * top[k] * double(N) + 1e-6 * mass);
                    }
            }
            // Directions left out are 0 where a copy rolls one at a time; the float form gives the double form's
            // value rounded (the sparse copy sums in double).
            std::vector<char> which(K, 0);
            which[1] = 1;
            std::vector<double> X(N * K), Y(N * K, 7.0);
            for (double& x : X) x = u(gen);
            sparse.apply(std::span<const double>(X), std::span<double>(Y), which);
            for (std::size_t i = 0; i < N; ++i) EXPECT_EQ(Y[i * K + 0], 0.0);
            std::vector<float> xf(X.begin(), X.end()), yf(N * K);
            std::vector<double> rounded(xf.begin(), xf.end()), yd(N * K);
            sparse.apply(std::span<const float>(xf), std::span<float>(yf));
            sparse.apply(std::span<const double>(rounded), std::span<double>(yd));
            for (std::size_t e = 0; e < yf.size(); ++e) EXPECT_EQ(yf[e], static_cast<float>(yd[e]));
            EXPECT_THROW(sparse.apply(std::span<const double>(X).first(N), std::span<double>(Y)), InputError);
            EXPECT_THROW(sparse.apply(std::span<const double>(X), std::span<double>(Y), std::vector<char>(K + 1, 1)),
                         InputError);
            EXPECT_EQ(reference.entries(), sparse.entries());
        }
}

// The rollouts are one algorithm over any copy: through the reference and the sparse copy they give the same
// returns, and replay the same weights, to the float32 rounding of the learned W's antisymmetry (the sparse copy
// multiplies a few active cells by columns).
TEST(AdjacencyProduct, RolloutsAndReplayReadAnyCopy) {
    const int n = 48;
    const HdAdjacency adj = learned_adjacency(n, 8, 3);
    const ReferenceAdjacency reference(adj, 0.0);
    const SparseAdjacency sparse(adj, 0.0);
    RewardParams p;
    p.lambda = 4;
    const auto w_ref = replay(reference, 5, p), w = replay(sparse, 5, p);
    for (int i = 0; i < n; ++i) EXPECT_NEAR(w[std::size_t(i)], w_ref[std::size_t(i)], 1e-6 * std::abs(w_ref[i]) + 1e-9);
    std::vector<double> v(std::size_t(n), 0.0);
    v[20] = 0.8, v[21] = 0.4;
    const auto r_ref = direction_returns(reference, w, v, p), r = direction_returns(sparse, w, v, p);
    for (int k = 0; k < 8; ++k) EXPECT_NEAR(r[std::size_t(k)], r_ref[std::size_t(k)], 1e-6 * std::abs(r_ref[k]) + 1e-9);
}

// Reward cells (population/reward_cells.hpp): a goal binds the most active place cell at learning steps inside its
// radius (in the plane for goals x, y), not outside it nor while frozen; the rates are the read-out w·v / |v|₁.
TEST(RewardCells, BindTheMostActiveCellNearTheGoalAndReadOutTheirWeights) {
    RewardCellParams p;
    p.goals = {1.0, 1.0, -2.0, 0.0};
    p.radius = 0.5;
    RewardCells cells(4, p);
    ASSERT_EQ(cells.size(), 2u);
    const auto at = [](double t, const Pose& pose) { return ModelStep{t, pose, false, std::nullopt}; };
    const std::vector<ModelStep> steps{at(0.0, Pose::on_floor(1.2, 1.1, 0.0)),   // near goal 1
                                       at(0.3, Pose::on_floor(1.2, 1.1, 0.0)),   // near goal 1, frozen
                                       at(0.6, Pose::on_floor(5.0, 5.0, 0.0)),   // near none
                                       at(0.9, Pose{-2.0, 0.3, 9.0, 0, 0, 0})};  // near goal 2 in the plane
    const std::vector<char> learn{1, 0, 1, 1};
    const std::vector<double> place{0.1, 0.5, 0.2, 0.0,   // goal 1 binds cell 1
                                    0.0, 0.0, 0.0, 0.9,   // frozen: no binding
                                    0.9, 0.0, 0.0, 0.0,   // far from both
                                    0.3, 0.0, 0.6, 0.1};  // goal 2 binds cell 2
    std::vector<double> out(8);
    const std::span<const double> in(place);
    cells.step(StepBlock{steps, learn, 0}, std::span<const std::span<const double>>(&in, 1), out);
    EXPECT_EQ(cells.bound(0), 1);
    EXPECT_EQ(cells.bound(1), 2);
    for (double r : out) EXPECT_EQ(r, 0.0);  // no weights before replay
    // Weights as replay would set them: the read-out of each step's rates.
    auto state = cells.state();
    for (auto& a : state)
        if (a.name == "reward_weights") a.values = std::vector<double>{1, 2, 3, 4, 0, 0, 1, 0};
    RewardCells again(4, p);
    again.restore(state);
    EXPECT_EQ(again.bound(0), 1);
    again.step(StepBlock{steps, std::vector<char>(4, 0), 0}, std::span<const std::span<const double>>(&in, 1), out);
    EXPECT_NEAR(out[0], (0.1 + 1.0 + 0.6) / 0.8, 1e-12);
    EXPECT_NEAR(out[7], 0.6 / 1.0, 1e-12);
    state.front().values = std::vector<double>{1, 7};  // cell 7 of 4
    EXPECT_THROW(again.restore(state), InputError);
    p.goals = {1.0, 1.0, 2.0};
    EXPECT_THROW(RewardCells(4, p), InputError);
}

// The learning walk (agent/learning_walk.hpp) is the robot's random walk step for step until each goal has been
// visited and the coverage reached, then has no steps left; saved and restored half way, it goes on the same.
TEST(LearningWalk, WalksAsTheRandomWalkUntilItsCriteriaAndResumesExactly) {
    test::TempDir dir;
    const World world = open_room(dir.path());
    NavigationSpaceSpec spec;
    spec.goals = {{2.5, 2.5}};
    spec.nav.goal_visits = 2;
    spec.nav.coverage = 0.6;
    const LearningWalkSpec learning(spec);
    const auto agent = learning.make(&world, 4);
    const auto plain = RandomWalkSpec(spec.robot).make(&world, 4);
    std::vector<Pose> poses;
    std::string half;
    while (const auto s = agent->next(1e6)) {
        const auto p = plain->next(1e6);
        ASSERT_TRUE(p.has_value());
        EXPECT_EQ(s->pose.x, p->pose.x);
        EXPECT_EQ(s->pose.y, p->pose.y);
        poses.push_back(s->pose);
        if (poses.size() == 300) half = agent->save_state();
    }
    EXPECT_TRUE(agent->finished());
    ASSERT_GT(poses.size(), 300u);
    const auto report = agent->report();
    ASSERT_EQ(report.size(), 3u);
    EXPECT_EQ(report[0].second, agent->time());
    EXPECT_GE(report[1].second, 0.6);
    EXPECT_GE(report[2].second, 2.0);
    // The criteria were met at the last step, not before: the coverage of the steps before it, by the space's cells.
    const auto space = make_navigation_space(world.description(), spec);
    std::vector<char> seen(space->coverage_size(), 0);
    std::size_t covered = 0;
    for (std::size_t i = 0; i + 1 < poses.size(); ++i)
        if (const auto c = space->coverage_cell(poses[i].position()); c && !seen[*c]) seen[*c] = 1, ++covered;
    int visits = 0;
    bool inside = false;
    for (std::size_t i = 0; i + 1 < poses.size(); ++i) {
        const bool in = space->distance(poses[i].position(), spec.goals[0].p) <= spec.nav.goal_radius;
        visits += in && !inside;
        inside = in;
    }
    EXPECT_TRUE(double(covered) / double(space->coverage_cells()) < 0.6 || visits < 2);
    const auto resumed = learning.make(&world, 99);
    resumed->restore_state(half);
    for (std::size_t i = 300; i < poses.size(); ++i) {
        const auto s = resumed->next(1e6);
        ASSERT_TRUE(s.has_value()) << i;
        EXPECT_EQ(s->pose.x, poses[i].x) << i;
        EXPECT_EQ(s->pose.heading, poses[i].heading) << i;
    }
    EXPECT_FALSE(resumed->next(1e6).has_value());
}

// The place-cell network (docs/model-reference.md#place-cell-network): dynamics, Oja learning, determinism.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "bvc3d/core/error.hpp"
#include "bvc3d/place/place_cell_network.hpp"

using namespace bvc3d;

namespace {
PlaceCellNetwork tiny_network() {
    PlaceParams p;
    p.n_place = 2;
    PlaceCellNetwork net(3, p, 0);
    net.set_weights(std::vector<float>{1, 0, 1, 0, 1, 0.5f});
    return net;
}
}  // namespace

TEST(PlaceCellNetwork, HandComputedTwoSteps) {
    // W = [[1, 0, 1], [0, 1, 0.5]], v_b = [0.5, 0.2, 0.1]: W·v_b = [0.6, 0.25], Σv_b = 0.8.
    // Step 1: s = 0.5·(W·v_b - 0.3·0.8 - 0.5·0) = [0.18, 0.005], v = tanh(s) = [0.178081, 0.0049999583].
    // Step 2: Σv = 0.183081; s0 = 0.18 + 0.5·(-0.18 + 0.6 - 0.24 - 0.0915404) = 0.2242298,
    //         s1 = 0.005 + 0.5·(-0.005 + 0.25 - 0.24 - 0.0915404) = -0.0382702, v = [0.2205459, 0].
    auto net = tiny_network();
    const std::vector<double> vb{0.5, 0.2, 0.1};
    auto v = net.step(vb, false);
    EXPECT_NEAR(net.membrane()[0], 0.18, 1e-6);
    EXPECT_NEAR(net.membrane()[1], 0.005, 1e-6);
    EXPECT_NEAR(v[0], 0.17808087, 1e-6);
    EXPECT_NEAR(v[1], 0.00499996, 1e-6);
    v = net.step(vb, false);
    EXPECT_NEAR(net.membrane()[0], 0.22422979, 1e-6);
    EXPECT_NEAR(net.membrane()[1], -0.03827021, 1e-6);
    EXPECT_NEAR(v[0], 0.22054585, 1e-6);
    EXPECT_EQ(v[1], 0.0f);  // rectified
}

TEST(PlaceCellNetwork, HandComputedOjaUpdate) {
    // After step 1 (v = [0.178081, 0.0049999583]) with learning on, eta = 0.096, alpha = √0.5:
    // W_ij += eta·v_i·(v_b,j - v_i·W_ij/alpha), e.g. W_00 = 1 + 0.0170958·(0.5 - 0.251844) = 1.0042424.
    auto net = tiny_network();
    net.step(std::vector<double>{0.5, 0.2, 0.1}, true);
    const auto w = net.weights();
    const double expected[6] = {1.00424241, 3.41915267e-03, 9.97404104e-01, 2.39998000e-04, 1.00009261, 5.00046303e-01};
    for (int i = 0; i < 6; ++i) EXPECT_NEAR(w[i], expected[i], 2e-7) << i;
}

TEST(PlaceCellNetwork, LearningOffLeavesWeightsUntouched) {
    PlaceCellNetwork net(960, PlaceParams{}, 5);
    const auto before = net.weights();
    std::mt19937_64 gen(1);
    std::uniform_real_distribution<double> u(0, 0.5);
    std::vector<double> vb(960);
    int active = 0;
    for (int t = 0; t < 200; ++t) {
        for (auto& x : vb) x = u(gen) * (u(gen) < 0.05);
        for (float r : net.step(vb, false)) active += r > 0;
    }
    EXPECT_GT(active, 0);
    EXPECT_EQ(net.weights(), before);
}

TEST(PlaceCellNetwork, WeightsStayBoundedOverALongRandomStream) {
    PlaceCellNetwork net(960, PlaceParams{}, 9);
    std::mt19937_64 gen(2);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<double> vb(960);
    float max_w = 0;
    int active_steps = 0;
    for (int t = 0; t < 20000; ++t) {
        // Sparse, bump-like BVC activity in [0, 0.5], as normalized layers give.
        const int center = static_cast<int>(u(gen) * 960);
        for (int j = 0; j < 960; ++j) {
            const int d = std::min(std::abs(j - center), 960 - std::abs(j - center));
            vb[j] = 0.5 * std::exp(-0.5 * d * d / 100.0) * (0.5 + 0.5 * u(gen));
        }
        bool any = false;
        for (float r : net.step(vb, true)) any = any || r > 0;
        active_steps += any;
    }
    for (float w : net.weights()) {
        ASSERT_TRUE(std::isfinite(w));
        max_w = std::max(max_w, std::abs(w));
    }
    EXPECT_GT(active_steps, 1000);
    // Oja's rule keeps |W_i| near alpha·|v_b|/v_i-scale: nothing runs away.
    EXPECT_LT(max_w, 5.0f);
}

TEST(PlaceCellNetwork, InitialWeightsAreSeededBernoulli) {
    const PlaceCellNetwork a(960, PlaceParams{}, 3), b(960, PlaceParams{}, 3), c(960, PlaceParams{}, 4);
    EXPECT_EQ(a.weights(), b.weights());
    EXPECT_NE(a.weights(), c.weights());
    double ones = 0;
    for (float w : a.weights()) {
        ASSERT_TRUE(w == 0.0f || w == 1.0f);
        ones += w;
    }
    EXPECT_NEAR(ones / (250.0 * 960.0), 0.25, 0.005);
    for (float v : a.rates()) EXPECT_EQ(v, 0.0f);
}

TEST(PlaceCellNetwork, SameInputsSameSeedBitIdentical) {
    PlaceCellNetwork a(960, PlaceParams{}, 11), b(960, PlaceParams{}, 11);
    std::mt19937_64 gen(3);
    std::uniform_real_distribution<double> u(0, 0.5);
    std::vector<double> vb(960);
    for (int t = 0; t < 500; ++t) {
        for (auto& x : vb) x = u(gen) * (u(gen) < 0.1);
        const auto ra = a.step(vb, true);
        const auto rb = b.step(vb, true);
        ASSERT_TRUE(std::equal(ra.begin(), ra.end(), rb.begin()));
    }
    EXPECT_EQ(a.weights(), b.weights());
}

// The drive W·v_b is summed in a fixed order (8 running lanes, column blocks in order, a fixed
// reduction tree) however many rows the kernel takes at once: checked bit for bit against that
// order written out in scalar code, for row counts that leave every remainder of the row blocking.
TEST(PlaceCellNetwork, DriveIsTheFixedOrderSumBitForBit) {
    for (int n_place : {1, 3, 4, 7, 250}) {
        PlaceParams p;
        p.n_place = n_place;
        p.gamma_pb = 0.0;  // s = k·drive exactly: the first step from rest, no inhibition
        const int n_bvc = 37;
        PlaceCellNetwork net(n_bvc, p, 4);
        std::mt19937_64 gen(n_place);
        std::uniform_real_distribution<float> u(0.0f, 1.0f);
        std::vector<float> w(static_cast<std::size_t>(n_place) * n_bvc);
        for (auto& x : w) x = u(gen);
        net.set_weights(w);
        std::vector<double> vb(n_bvc);
        for (auto& x : vb) x = static_cast<float>(u(gen) * 0.5f);
        net.step(vb, false);
        const float k = static_cast<float>(p.dt_over_tau);
        for (int i = 0; i < n_place; ++i) {
            float lane[8] = {0, 0, 0, 0, 0, 0, 0, 0};
            for (int j = 0; j < n_bvc; ++j)
                lane[j % 8] += w[static_cast<std::size_t>(i) * n_bvc + j] * static_cast<float>(vb[j]);
            const float drive =
                ((lane[0] + lane[1]) + (lane[2] + lane[3])) + ((lane[4] + lane[5]) + (lane[6] + lane[7]));
            const float s = 0.0f + k * (-0.0f + drive - 0.0f);
            ASSERT_EQ(net.membrane()[i], s) << n_place << " cells, row " << i;
        }
    }
}

// The products skip blocks of 8 inputs that are 0 in every step of a tile; that must leave every sum's bits as the
// sum over all columns gives them (w·0 = −0 for w < 0 included). Weights of both signs; inputs with blocks zero in
// every step, zero in some steps only, or with a single value not 0; blocks of several steps (tiles and the steps
// left) with learning off, against the recursion s ← s + k·(−s + drive) in scalar code.
TEST(PlaceCellNetwork, ZeroInputBlocksChangeNoBit) {
    const int n_bvc = 130, n_place = 7;
    PlaceParams p;
    p.n_place = n_place;
    p.gamma_pb = 0.0;  // no inhibition: s ← s + k·(−s + drive)
    p.gamma_pp = 0.0;
    std::mt19937_64 gen(9);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<float> w(static_cast<std::size_t>(n_place) * n_bvc);
    for (auto& x : w) x = u(gen);
    for (const int steps : {1, 3, 8, 11, 16}) {
        PlaceCellNetwork net(n_bvc, p, 4);
        net.set_weights(w);
        std::vector<double> vb(static_cast<std::size_t>(steps) * n_bvc);
        int zero_blocks = 0;
        for (int t = 0; t < steps; ++t)
            for (int j = 0; j < n_bvc; ++j) {
                const int block = j / 8;
                const bool zero = block % 3 == 0 || (block % 3 == 1 && t % 2 == 0) || (block == 5 && j != 43);
                zero_blocks += zero && j % 8 == 0;
                vb[static_cast<std::size_t>(t) * n_bvc + j] = zero ? 0.0 : 0.5 * (u(gen) + 1.0f);
            }
        ASSERT_GT(zero_blocks, 4 * steps);
        net.step_block(vb, std::vector<char>(static_cast<std::size_t>(steps), 0));
        const float k = static_cast<float>(p.dt_over_tau);
        for (int i = 0; i < n_place; ++i) {
            float s = 0.0f;
            for (int t = 0; t < steps; ++t) {
                float lane[8] = {0, 0, 0, 0, 0, 0, 0, 0};
                for (int j = 0; j < n_bvc; ++j)
                    lane[j % 8] += w[static_cast<std::size_t>(i) * n_bvc + j] *
                                   static_cast<float>(vb[static_cast<std::size_t>(t) * n_bvc + j]);
                const float drive =
                    ((lane[0] + lane[1]) + (lane[2] + lane[3])) + ((lane[4] + lane[5]) + (lane[6] + lane[7]));
                s = s + k * (-s + drive - 0.0f);
            }
            ASSERT_EQ(net.membrane()[i], s) << steps << " steps, row " << i;
        }
    }
}

// The grid drive W_g·c (W_g a 0/1 mask, read by columns where a grid cell fires) is the fixed-order 8-lane sum over
// every column, bit for bit: grid rates mostly 0 as a module's are, cell and grid counts that are not multiples of 8
// or 16, several steps in a block (learning off), against s ← s + k·(−s + (1−g)·W_b·b + g·W_g·c) in scalar code.
TEST(PlaceCellNetwork, GridDriveIsTheFixedOrderSumBitForBit) {
    const int n_bvc = 24, n_grid = 37, n_place = 19, steps = 11;
    PlaceParams p;
    p.n_place = n_place;
    p.gamma_pb = p.gamma_pg = p.gamma_pp = 0.0;  // no inhibition
    p.grid_influence = 0.3;
    PlaceCellNetwork net(n_bvc, p, 6, n_grid);
    std::mt19937_64 gen(2);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<double> vb(static_cast<std::size_t>(steps) * n_bvc), vg(static_cast<std::size_t>(steps) * n_grid);
    for (auto& x : vb) x = u(gen) < 0.5 ? 0.0 : u(gen);
    int firing = 0;
    for (auto& x : vg) {
        x = u(gen) < 0.7 ? 0.0 : u(gen);
        firing += x > 0;
    }
    ASSERT_GT(firing, 40);
    const auto w = net.weights();
    const auto m = net.grid_mask();
    int ones = 0;
    for (float x : m) ones += x == 1.0f;
    ASSERT_GT(ones, 100);
    net.step_block(vb, vg, std::vector<char>(steps, 0));
    const auto sum = [](const float* row, const double* x, int n) {
        float lane[8] = {0, 0, 0, 0, 0, 0, 0, 0};
        for (int j = 0; j < n; ++j) lane[j % 8] += row[j] * static_cast<float>(x[j]);
        return ((lane[0] + lane[1]) + (lane[2] + lane[3])) + ((lane[4] + lane[5]) + (lane[6] + lane[7]));
    };
    const float k = static_cast<float>(p.dt_over_tau), kb = static_cast<float>(1.0 - p.grid_influence),
                kg = static_cast<float>(p.grid_influence);
    for (int i = 0; i < n_place; ++i) {
        float s = 0.0f;
        for (int t = 0; t < steps; ++t) {
            const float drive =
                kb * sum(&w[static_cast<std::size_t>(i) * n_bvc], &vb[static_cast<std::size_t>(t) * n_bvc], n_bvc) +
                kg * sum(&m[static_cast<std::size_t>(i) * n_grid], &vg[static_cast<std::size_t>(t) * n_grid], n_grid);
            s = s + k * (-s + drive - 0.0f);
        }
        ASSERT_EQ(net.membrane()[i], s) << "row " << i;
    }
}

// A weight that Oja's rule makes infinite stops the network at once (the products, which skip inputs that are 0,
// rely on finite weights).
TEST(PlaceCellNetwork, WeightsThatRunAwayStopTheNetwork) {
    PlaceParams p;
    p.n_place = 2;
    p.gamma_pb = 0.0;
    p.eta = 1e6;
    PlaceCellNetwork net(16, p, 1);
    net.set_weights(std::vector<float>(32, 1e36f));  // Oja: 1e36 − 1e6·(1e36·√2 − 0.5) = −inf
    std::vector<double> vb(16, 0.0);
    vb[0] = 0.5;
    EXPECT_THROW(net.step(vb, true), InputError);
}

// Rates and weights below the smallest normal float in magnitude are taken as 0 (no subnormal number
// enters the arithmetic): a network fed such rates behaves bit for bit like one fed zeros there, and
// no weight is ever subnormal, even when Oja's rule is fed Gaussian tails down to 1e-300.
TEST(PlaceCellNetwork, SubnormalOperandsAreZeros) {
    PlaceCellNetwork tiny(960, PlaceParams{}, 8), zero(960, PlaceParams{}, 8);
    std::vector<double> vb(960), vz(960);
    std::mt19937_64 gen(5);
    std::uniform_real_distribution<double> u(0, 1);
    int active = 0, subnormal_inputs = 0;
    for (int t = 0; t < 3000; ++t) {
        const int center = static_cast<int>(u(gen) * 960);
        for (int j = 0; j < 960; ++j) {
            const double d = std::abs(j - center);
            vb[j] = 0.5 * std::exp(-0.5 * d * d / 400.0);  // down to 1e-300 and exact zeros
            const float f = static_cast<float>(vb[j]);
            vz[j] = f != 0.0f && std::fpclassify(f) == FP_SUBNORMAL ? 0.0 : vb[j];
            subnormal_inputs += vz[j] != vb[j];
        }
        const auto a = tiny.step(vb, true);
        const auto b = zero.step(vz, true);
        ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin())) << t;
        for (float r : a) active += r > 0;
    }
    EXPECT_GT(active, 100);
    EXPECT_GT(subnormal_inputs, 1000);
    int subnormal = 0, tiny_weights = 0;
    for (float x : tiny.weights()) {
        subnormal += std::fpclassify(x) == FP_SUBNORMAL;
        tiny_weights += x != 0.0f && std::abs(x) < 1e-30f;  // Oja did write weights near the limit
    }
    EXPECT_EQ(subnormal, 0);
    EXPECT_GT(tiny_weights, 0);
    // Weights given from outside are taken the same way.
    std::vector<float> w(250 * 960, 0.25f);
    w[5] = 1e-30f;
    w[6] = -1e-40f;
    tiny.set_weights(w);
    EXPECT_EQ(tiny.weights()[5], 1e-30f);
    EXPECT_EQ(tiny.weights()[6], 0.0f);
    EXPECT_EQ(tiny.weights()[7], 0.25f);
}

TEST(PlaceCellNetwork, ResetAndWeightsRoundTrip) {
    PlaceCellNetwork net(960, PlaceParams{}, 1);
    std::vector<double> vb(960, 0.0);
    for (int j = 0; j < 100; ++j) vb[j] = 0.5;
    net.step(vb, true);
    auto w = net.weights();
    w[7] = 0.123f;
    net.set_weights(w);
    EXPECT_EQ(net.weights(), w);
    net.reset();
    for (float s : net.membrane()) EXPECT_EQ(s, 0.0f);
    for (float v : net.rates()) EXPECT_EQ(v, 0.0f);
    EXPECT_EQ(net.weights(), w);
    EXPECT_THROW(net.set_weights(std::vector<float>(10)), InputError);
    EXPECT_THROW(net.step(std::vector<double>(959), true), InputError);
    vb[3] = NAN;
    EXPECT_THROW(net.step(vb, true), InputError);
    PlaceParams bad;
    bad.n_place = 0;
    EXPECT_THROW(PlaceCellNetwork(960, bad, 0), InputError);
}

// step_block (one pass over the weights for several steps, the rows Oja's rule changed multiplied
// again) gives the bits of step() called step after step: rates of every step, membrane, weights;
// for blocks longer and shorter than the kernels' tiles, learning switched on and off inside a block,
// odd cell counts (a pair's second row empty) and BVC counts that are not a multiple of 8.
TEST(PlaceCellNetwork, StepBlockIsStepAfterStep) {
    for (const auto& [n_place, n_bvc] : {std::pair{250, 960}, std::pair{17, 37}, std::pair{1, 8}, std::pair{6, 130}}) {
        PlaceParams p;
        p.n_place = n_place;
        if (n_place < 100) p.gamma_pb = 0.02;  // small networks fire only under weak inhibition
        PlaceCellNetwork stepped(n_bvc, p, 21), blocked(n_bvc, p, 21);
        std::mt19937_64 gen(static_cast<unsigned>(n_place));
        std::uniform_real_distribution<double> u(0, 1);
        int active = 0;
        std::size_t learned_steps = 0;
        for (const int steps : {16, 1, 3, 8, 9, 20, 16, 16, 5, 16}) {
            std::vector<double> rates(static_cast<std::size_t>(steps) * n_bvc);
            std::vector<char> learn(static_cast<std::size_t>(steps));
            for (int t = 0; t < steps; ++t) {
                const double center = u(gen) * n_bvc;  // a bump of BVC activity: some cells fire and learn
                for (int j = 0; j < n_bvc; ++j)
                    rates[static_cast<std::size_t>(t) * n_bvc + j] =
                        0.5 * std::exp(-0.5 * (j - center) * (j - center) / 400.0);
                learn[static_cast<std::size_t>(t)] = u(gen) < 0.8;
                learned_steps += learn[static_cast<std::size_t>(t)] != 0;
            }
            const auto block = blocked.step_block(rates, learn);
            ASSERT_EQ(block.size(), static_cast<std::size_t>(steps) * n_place);
            for (int t = 0; t < steps; ++t) {
                const auto v =
                    stepped.step(std::span<const double>(rates.data() + static_cast<std::size_t>(t) * n_bvc, n_bvc),
                                 learn[static_cast<std::size_t>(t)] != 0);
                for (int i = 0; i < n_place; ++i) {
                    ASSERT_EQ(block[static_cast<std::size_t>(t) * n_place + i], v[i])
                        << n_place << " cells, step " << t;
                    active += v[i] > 0;
                }
            }
            ASSERT_TRUE(std::equal(stepped.membrane().begin(), stepped.membrane().end(), blocked.membrane().begin()));
            ASSERT_EQ(stepped.weights(), blocked.weights()) << n_place << " cells";
        }
        EXPECT_GT(active, 10) << n_place << " cells: the inputs should make some cells fire and learn";
        EXPECT_GT(learned_steps, 50u);
    }
}

// A block with a bad input anywhere changes nothing: every input is checked before the first step.
TEST(PlaceCellNetwork, StepBlockChecksEveryInputFirst) {
    PlaceCellNetwork net(16, PlaceParams{}, 2);
    std::vector<double> rates(3 * 16, 0.25);
    EXPECT_THROW(net.step_block(rates, std::vector<char>(2, 1)), InputError);  // 3 steps of rates, 2 flags
    rates[2 * 16 + 5] = NAN;
    const auto weights = net.weights();
    EXPECT_THROW(net.step_block(rates, std::vector<char>(3, 1)), InputError);
    EXPECT_EQ(net.weights(), weights);
    for (float s : net.membrane()) EXPECT_EQ(s, 0.0f);
    EXPECT_TRUE(net.step_block({}, {}).empty());
}

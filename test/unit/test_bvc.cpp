// Boundary vector cells (docs/model-reference.md#boundary-vector-cells) against the literal equations.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <random>

#include "../support/bvc_reference.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/bvc/bvc_kernels.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"

using namespace bvc3d;

namespace {

// |fast - reference| <= 1e-6 of the step's largest reference rate, for every cell
// (docs/model-reference.md#boundary-vector-cells).
void expect_matches_reference(const BvcParams& p, const Scan& returns, const std::string& what) {
    const BoundaryVectorLayer layer(p);
    std::vector<double> fast(layer.n_cells());
    layer.rates(returns, fast);
    const auto ref = reference::bvc_rates(p, returns);
    ASSERT_EQ(fast.size(), ref.size());
    double largest = 0, worst = 0;
    for (double v : ref) largest = std::max(largest, v);
    for (std::size_t i = 0; i < ref.size(); ++i) {
        ASSERT_TRUE(std::isfinite(fast[i]));
        worst = std::max(worst, std::abs(fast[i] - ref[i]));
    }
    EXPECT_LE(worst, 1e-6 * largest) << what << ": worst error " << worst << " vs largest rate " << largest;
}

Scan random_returns(std::mt19937_64& gen, int n, double phi_lo, double phi_hi) {
    std::uniform_real_distribution<double> range(0.0, 18.0), az(-M_PI, M_PI), el(phi_lo, phi_hi);
    Scan s;
    for (int i = 0; i < n; ++i) s.push_back({range(gen), az(gen), el(gen)});
    return s;
}

std::vector<BvcParams> all_configs() {
    std::vector<BvcParams> configs;
    for (const auto& name : model_preset_names()) configs.push_back(model_preset(name).bvc);
    BvcParams odd;
    odd.elevations = {-0.3, 0.0, 0.05, 0.4, 1.2};  // many layers, some below the horizon
    odd.n_dir = 3;
    odd.n_per_axis = 17;
    odd.sigma_phi = 0.05;
    configs.push_back(odd);
    BvcParams wide;  // angular window wider than the circle; single distance cell
    wide.n_dir = 1;
    wide.n_per_axis = 1;
    wide.sigma_theta = 1.57;
    configs.push_back(wide);
    BvcParams coarse;  // cells further apart than sigma_r: the direct (non-recurrence) path
    coarse.elevations = {0.1};
    coarse.n_dir = 16;
    coarse.n_per_axis = 5;
    coarse.sigma_r = 0.3;
    configs.push_back(coarse);
    return configs;
}

}  // namespace

namespace {

// What the layer reads of each return before its bookkeeping, as the scalar formulas give it: no
// return (a NaN or +inf range), the azimuth wrapped to (-π, π], its memo slot, and the distance
// window m_lo..m_hi (cells within r ± cut; empty if m_lo > m_hi), widened to whole blocks of 8.
struct ScalarReading {
    bool absent = false;
    double azimuth = 0, x0 = 0;
    int slot = 0, first = 0, width = 0;
};

ScalarReading scalar_reading(const LidarReturn& r, const kernels::ReturnRule& rule) {
    ScalarReading e;
    e.absent = std::isnan(r.range) || r.range == INFINITY;
    if (e.absent) return e;
    e.azimuth = wrap_pi(r.azimuth);
    const auto s = static_cast<long>(std::floor((e.azimuth + M_PI) * rule.slot_scale));
    e.slot = static_cast<int>(std::min<long>(s, rule.slots - 1));
    int m_lo = 0, m_hi = 0;
    if (rule.dd > 0) {
        const double lo = (r.range - rule.cut) * rule.inv_dd, hi = (r.range + rule.cut) * rule.inv_dd;
        m_lo = lo > 0 ? static_cast<int>(std::floor(std::min(lo, 1e9))) : 0;
        m_hi = static_cast<int>(std::floor(std::min(hi, rule.cells - 2.0))) + 1;
    } else {
        m_lo = r.range > rule.cut ? 1 : 0;
    }
    if (m_lo > m_hi) return e;  // width 0
    e.first = rule.aligned ? m_lo / 8 * 8 : m_lo;
    e.width = rule.aligned ? (m_hi / 8 + 1) * 8 - e.first : m_hi - m_lo + 1;
    e.x0 = r.range - e.first * rule.dd;
    return e;
}

std::vector<simd::Isa> isas_of_this_cpu() {
    std::vector<simd::Isa> isas{simd::Isa::baseline};
    __builtin_cpu_init();
    if (__builtin_cpu_supports("x86-64-v3")) isas.push_back(simd::Isa::v3);
    if (__builtin_cpu_supports("x86-64-v4")) isas.push_back(simd::Isa::v4);
    return isas;
}

}  // namespace

TEST(BvcKernels, ReturnReadingsAreTheScalarFormulasOnEveryInstructionSet) {
    std::mt19937_64 gen(11);
    std::uniform_real_distribution<double> range(0.0, 16.0), az(-M_PI, M_PI), el(-1.0, 1.0), turns(-40.0, 40.0);
    Scan returns;
    for (int i = 0; i < 1000; ++i) returns.push_back({range(gen), az(gen), el(gen)});
    // Azimuths a turn out, many turns out, on the boundaries; ranges on window edges, far, absent.
    for (double a :
         {M_PI, -M_PI, 2 * M_PI, -2 * M_PI, 3 * M_PI, -3 * M_PI, 2.9 * M_PI, -2.9 * M_PI, 1e6, -1e9, 0.0, -0.0})
        returns.push_back({3.0, a, 0.1});
    for (int i = 0; i < 40; ++i) returns.push_back({range(gen), turns(gen), el(gen)});
    for (double r : {0.0, 0.75, 12.0, 12.0 + 4.5, 1e3, 1e300, static_cast<double>(NAN), static_cast<double>(INFINITY)})
        returns.push_back({r, az(gen), 0.0});
    std::shuffle(returns.begin(), returns.end(), gen);
    for (const bool aligned : {true, false}) {
        for (const int cells : {60, 120, 1}) {
            const double dd = cells > 1 ? 12.0 / (cells - 1) : 0.0;
            const kernels::ReturnRule rule{4.5, dd, dd > 0 ? 1 / dd : 0.0, cells, aligned, 360 / (2 * M_PI), 360};
            for (const simd::Isa isa : isas_of_this_cpu()) {
                for (std::size_t j = 0; j < returns.size(); j += kernels::ReturnReadings::size) {
                    const std::size_t n = std::min(kernels::ReturnReadings::size, returns.size() - j);
                    kernels::ReturnReadings in;
                    ASSERT_EQ(kernels::read_returns(&returns[j].range, n, rule, in, isa), n);
                    for (std::size_t k = 0; k < n; ++k) {
                        const ScalarReading e = scalar_reading(returns[j + k], rule);
                        const std::string where = "isa " + std::to_string(static_cast<int>(isa)) + ", cells " +
                                                  std::to_string(cells) + ", return " + std::to_string(j + k);
                        ASSERT_EQ(in.absent[k] != 0, e.absent) << where;
                        if (e.absent) continue;
                        EXPECT_EQ(std::bit_cast<std::uint64_t>(in.azimuth[k]), std::bit_cast<std::uint64_t>(e.azimuth))
                            << where;
                        EXPECT_EQ(in.slot[k], e.slot) << where;
                        EXPECT_EQ(in.width[k], e.width) << where;
                        if (e.width == 0) continue;
                        EXPECT_EQ(in.first[k], e.first) << where;
                        EXPECT_EQ(std::bit_cast<std::uint64_t>(in.x0[k]), std::bit_cast<std::uint64_t>(e.x0)) << where;
                    }
                }
            }
        }
    }
    // The first invalid return of a batch is found, wherever it is and whatever comes before it.
    const kernels::ReturnRule rule{4.5, 0.2, 5.0, 61, true, 360 / (2 * M_PI), 360};
    for (const LidarReturn bad :
         {LidarReturn{-1.0, 0.0, 0.0}, LidarReturn{-INFINITY, 0.0, 0.0}, LidarReturn{1.0, NAN, 0.0},
          LidarReturn{1.0, INFINITY, 0.0}, LidarReturn{1.0, 0.0, NAN}, LidarReturn{1.0, 0.0, -INFINITY}}) {
        for (const std::size_t at : {0, 5, 8, 37, 63}) {
            Scan batch(returns.begin(), returns.begin() + 64);
            batch[at] = bad;
            if (at + 1 < batch.size()) batch[at + 1] = {-2.0, 0.0, 0.0};  // a later invalid one is not the first
            for (const simd::Isa isa : isas_of_this_cpu()) {
                kernels::ReturnReadings in;
                EXPECT_EQ(kernels::read_returns(&batch[0].range, batch.size(), rule, in, isa), at);
            }
        }
    }
}

TEST(BoundaryVectorLayer, MatchesTheEquationsOnRandomReturns) {
    std::mt19937_64 gen(7);
    for (const auto& p : all_configs()) {
        for (int trial = 0; trial < 3; ++trial) {
            Scan s = random_returns(gen, 400, -0.5, 0.6);
            // Awkward cases: azimuth exactly ±π, elevations outside every layer, range 0 and beyond max.
            s.push_back({3.0, M_PI, 0.0});
            s.push_back({3.0, -M_PI, 0.1});
            s.push_back({0.0, 0.5, 0.2});
            s.push_back({25.0, 0.0, 0.0});
            s.push_back({4.0, 1.0, 1.5});
            expect_matches_reference(p, s, "random returns, " + std::to_string(p.n_dir) + " dirs");
        }
        // Only a few returns, all at one elevation that matches no layer: sums are tiny but still exact.
        Scan sparse = {{2.0, 0.3, 0.7}, {5.0, -2.0, 0.7}};
        expect_matches_reference(p, sparse, "sparse returns");
    }
}

// Every preset sees two of the four paper worlds, one scan in each, and every world is seen by a quarter of
// the presets in each turn: the reference is slow on the LiDAR models' large scans (and slower under ASan).
TEST(BoundaryVectorLayer, MatchesTheEquationsOnRealScansOfEveryPaperWorld) {
    const double tilts[] = {0.0, 30.0, 45.0, 60.0};
    std::vector<World> worlds;
    std::vector<std::vector<ModelStep>> walks;
    for (double tilt : tilts) {
        worlds.push_back(World::cross({.tilt_deg = tilt}));
        walks.push_back(random_walk(worlds.back(), 0.05, 3));
    }
    const auto names = model_preset_names();
    for (std::size_t k = 0; k < names.size(); ++k) {
        const ModelSpec m = model_preset(names[k]);
        const Lidar lidar(m.sensor);
        for (const std::size_t w : {k % 4, (k + 2) % 4}) {
            const auto& walk = walks[w];
            const Scan scan = lidar.scan(worlds[w], walk[w < 2 ? walk.size() / 3 : walk.size() - 1].pose);
            expect_matches_reference(m.bvc, scan, names[k] + " in cross-" + std::to_string(int(tilts[w])));
        }
    }
}

TEST(BoundaryVectorLayer, PrunedScanningGivesTheSameRates) {
    const World world = World::cross({.tilt_deg = 45});
    // The authors' image labels too: plans read the rows' labels, and the bound allows for linspace's
    // repeated azimuth.
    for (const char* name : {"3d-0.1", "3d-0.2", "3d-3l", "3d-0.1-authors", "3d-0.2-authors", "3d-3l-authors"}) {
        const ModelSpec m = model_preset(name);
        const BoundaryVectorLayer layer(m.bvc);
        const Lidar lidar(m.sensor);
        const auto plan = layer.plan(m.sensor);
        const auto& rows = plan.rows;
        int cast = 0;
        for (char r : rows) cast += r;
        EXPECT_LE(cast, 7) << name << " should need only the rows near its layers";
        for (const Pose pose : {Pose::on_floor(4, 4, 0.2), Pose::on_floor(0.7, -0.9, -1)}) {
            Scan full, pruned;
            lidar.scan(world, pose, full);
            lidar.scan(world, pose, pruned, {}, rows);
            std::vector<double> a(layer.n_cells()), b(layer.n_cells());
            layer.rates(full, a);
            ASSERT_TRUE(layer.rates_pruned(pruned, plan, b));
            const auto ref = reference::bvc_rates(m.bvc, full);
            for (std::size_t i = 0; i < a.size(); ++i) {
                EXPECT_NEAR(a[i], ref[i], 0.5e-6);
                EXPECT_NEAR(b[i], ref[i], 0.5e-6);
            }
        }
    }
}

// The azimuth memo and the one-call kernel are for speed only: a layer that has seen a walk's scans
// (its memo filled, switched off and on) gives each scan exactly the bits a fresh layer gives.
TEST(BoundaryVectorLayer, RatesDoNotDependOnWhatTheLayerSawBefore) {
    const World world = World::cross({.tilt_deg = 30});
    const auto walk = random_walk(world, 0.02, 5);
    for (const char* name : {"2d", "3d-3l"}) {
        const ModelSpec m = model_preset(name);
        const BoundaryVectorLayer used(m.bvc);
        const Lidar lidar(m.sensor);
        const auto plan = used.plan(m.sensor);
        std::vector<double> a(used.n_cells()), b(used.n_cells());
        Scan scan, shuffled;
        std::mt19937_64 gen(1);
        for (std::size_t i = 0; i < walk.size(); i += 3) {
            lidar.scan(world, walk[i].pose, scan, {}, plan.rows);
            ASSERT_TRUE(used.rates_pruned(scan, plan, a));
            const BoundaryVectorLayer fresh(m.bvc);
            ASSERT_TRUE(fresh.rates_pruned(scan, plan, b));
            ASSERT_EQ(a, b) << name << " step " << i;
            // Irregular returns (a shuffled scan repeats no azimuth from one return to the next).
            shuffled = scan;
            std::shuffle(shuffled.begin(), shuffled.end(), gen);
            used.rates(shuffled, a);
            fresh.rates(shuffled, b);
            ASSERT_EQ(a, b) << name << " step " << i << ", shuffled";
        }
    }
}

// Models on one walk that differ only in their elevations read their sums from one layer that
// summed the union once (the experiment engine does so): the same bits and the same verdict of the
// truncation bound as each summing on its own, whatever the other layers and the order of the union.
TEST(BoundaryVectorLayer, SharedSumsGiveEveryModelItsOwnBits) {
    const World world = World::cross({.tilt_deg = 45});
    const auto walk = random_walk(world, 0.02, 11);
    const ModelSpec base = model_preset("3d-3l");
    std::vector<BvcParams> models;
    for (const std::vector<double>& e :
         std::vector<std::vector<double>>{{0.0, 0.1}, {0.0, 0.2}, {0.0, 0.1, 0.2}, {0.3}, {0.25, 0.0}}) {
        BvcParams p = base.bvc;
        p.elevations = e;
        models.push_back(p);
    }
    BvcParams all = base.bvc;
    all.elevations = {0.3, 0.2, 0.25, 0.0, 0.1};
    const BoundaryVectorLayer summed(all);
    const auto all_plan = summed.plan(base.sensor);
    const Lidar lidar(base.sensor);
    // Every model, summing on its own and reading `summed`'s sums of the same scan: same verdict, same bits.
    auto expect_readers_match = [&](const Scan& scan, const std::string& what) {
        summed.sum_pruned(scan, all_plan);
        for (const auto& p : models) {
            const BoundaryVectorLayer own(p), reader(p);
            const auto plan = own.plan(base.sensor);
            std::vector<double> a(own.n_cells()), b(own.n_cells());
            const bool ok_own = own.rates_pruned(scan, plan, a);
            ASSERT_EQ(reader.rates_pruned_shared(scan, plan, summed, b), ok_own) << what;
            if (ok_own) {
                ASSERT_EQ(a, b) << what << ", elevations[0] " << p.elevations[0];
            }
        }
    };
    Scan scan;
    std::mt19937_64 gen(3);
    for (std::size_t i = 0; i < walk.size(); i += 7) {
        lidar.scan(world, walk[i].pose, scan, {}, all_plan.rows);
        expect_readers_match(scan, "step " + std::to_string(i));
        // Irregular order (no rows to total): each reader's bound then comes from its own pass.
        Scan shuffled = scan;
        std::shuffle(shuffled.begin(), shuffled.end(), gen);
        expect_readers_match(shuffled, "shuffled, step " + std::to_string(i));
    }
    // The bound's verdict is each reader's own: nothing in reach is declined.
    summed.sum_pruned(Scan{}, all_plan);
    const BoundaryVectorLayer first(models[0]);
    std::vector<double> v(first.n_cells());
    EXPECT_FALSE(first.rates_pruned_shared(Scan{}, first.plan(base.sensor), summed, v));
    // Planar layers share with planar ones.
    const ModelSpec flat = model_preset("2d");
    const BoundaryVectorLayer flat_sum(flat.bvc), flat_reader(flat.bvc);
    const auto flat_plan = flat_sum.plan(flat.sensor);
    const Lidar flat_lidar(flat.sensor);
    flat_lidar.scan(world, walk[5].pose, scan);
    flat_sum.sum_pruned(scan, flat_plan);
    std::vector<double> a(flat_sum.n_cells()), b(flat_sum.n_cells());
    ASSERT_TRUE(flat_sum.rates_pruned(scan, flat_plan, a));
    ASSERT_TRUE(flat_reader.rates_pruned_shared(scan, flat_plan, flat_sum, b));
    EXPECT_EQ(a, b);
    // Sums of other parameters, or without one of the reader's elevations, are refused.
    EXPECT_FALSE(flat_reader.can_share_sums(all));
    BvcParams wider = models[0];
    wider.sigma_r = 0.5;
    EXPECT_THROW(
        BoundaryVectorLayer(wider).rates_pruned_shared(scan, BoundaryVectorLayer(wider).plan(base.sensor), summed, v),
        InputError);
    BvcParams missing = models[0];
    missing.elevations = {0.15};
    EXPECT_THROW(BoundaryVectorLayer(missing).rates_pruned_shared(scan, BoundaryVectorLayer(missing).plan(base.sensor),
                                                                  summed, v),
                 InputError);
}

TEST(BoundaryVectorLayer, ScanPlansCastOnlyTheRowsThatMatter) {
    // Rows of the spherical scanner are at 89°, 87°, ..., 1°. With sigma_phi = 0.01 rad a row counts
    // when its weight exceeds 1e-8 of the peak: 1°, 3° for the 0-rad layer, 3°..9° for 0.1 rad,
    // 9°..13° for 0.2 rad (the +15° row, 5e-9 of the peak, is left to the plan's bound).
    auto cast_rows = [](const char* preset) {
        const ModelSpec m = model_preset(preset);
        const auto plan = BoundaryVectorLayer(m.bvc).plan(m.sensor);
        std::vector<int> degrees;
        for (std::size_t i = 0; i < plan.rows.size(); ++i)
            if (plan.rows[i]) degrees.push_back(static_cast<int>(std::lround(m.sensor.elevations[i] * 180 / M_PI)));
        return degrees;
    };
    EXPECT_EQ(cast_rows("3d-0.1"), (std::vector<int>{9, 7, 5, 3, 1}));
    EXPECT_EQ(cast_rows("3d-0.2"), (std::vector<int>{13, 11, 9, 3, 1}));
    EXPECT_EQ(cast_rows("3d-3l"), (std::vector<int>{13, 11, 9, 7, 5, 3, 1}));
    EXPECT_EQ(cast_rows("2d").size(), 1u);
    // A scan the bound cannot vouch for (nothing in reach) is declined, so the caller casts it all.
    const ModelSpec m = model_preset("3d-0.2");
    const BoundaryVectorLayer layer(m.bvc);
    std::vector<double> v(layer.n_cells());
    EXPECT_FALSE(layer.rates_pruned(Scan{}, layer.plan(m.sensor), v));
    EXPECT_FALSE(layer.rates_pruned(Scan{{19.0, 0.3, 0.2}}, layer.plan(m.sensor), v));
}

TEST(BoundaryVectorLayer, CellOrderAndPreferredValues) {
    // One return straight east at 6.1 m, elevation 0.2: the peak is layer 0.2, direction 0, d_m ≈ 6.1.
    BvcParams p = model_preset("3d-0.2").bvc;
    const BoundaryVectorLayer layer(p);
    std::vector<double> v(layer.n_cells());
    layer.rates(Scan{{6.1, 0.0, 0.2}}, v);
    const auto peak = std::max_element(v.begin(), v.end()) - v.begin();
    const int M = p.n_per_axis, K = p.n_dir;
    EXPECT_EQ(peak / (K * M), 1);  // layer index of psi = 0.2
    EXPECT_EQ((peak / M) % K, 0);  // direction east
    EXPECT_NEAR((peak % M) * p.spacing(), 6.1, p.spacing() / 2);
    // A return to the north-west lands in direction 3 (135°).
    layer.rates(Scan{{3.0, 3 * M_PI / 4, 0.0}}, v);
    const auto nw = std::max_element(v.begin(), v.end()) - v.begin();
    EXPECT_EQ(nw / (K * M), 0);
    EXPECT_EQ((nw / M) % K, 3);
}

TEST(BoundaryVectorLayer, ElevationFactorSelectsTheLayer) {
    const BvcParams p = model_preset("3d-0.2").bvc;
    const BoundaryVectorLayer layer(p);
    std::vector<double> raw(layer.n_cells());
    layer.raw(Scan{{4.0, 0.0, 0.2}}, raw);
    const std::size_t per_layer = p.n_dir * p.n_per_axis;
    const double low = *std::max_element(raw.begin(), raw.begin() + per_layer);
    const double high = *std::max_element(raw.begin() + per_layer, raw.end());
    EXPECT_GT(high, 0.0);
    EXPECT_LT(low, 1e-80 * high);  // 0.2 rad = 20 sigma_phi from the 0-rad layer
    // The 2-D model ignores elevation entirely.
    const BoundaryVectorLayer flat(model_preset("2d").bvc);
    std::vector<double> a(flat.n_cells()), b(flat.n_cells());
    flat.raw(Scan{{4.0, 0.0, 0.2}}, a);
    flat.raw(Scan{{4.0, 0.0, 0.0}}, b);
    EXPECT_EQ(a, b);
}

TEST(BoundaryVectorLayer, NormalisationModes) {
    const World world = World::cross({.tilt_deg = 30});
    const ModelSpec m = model_preset("3d-3l");
    const Scan scan = Lidar(m.sensor).scan(world, Pose::on_floor(1, 1, 0));
    const BoundaryVectorLayer layer(m.bvc);
    std::vector<double> v(layer.n_cells()), raw(layer.n_cells());
    layer.rates(scan, v);
    layer.raw(scan, raw);
    EXPECT_EQ(*std::max_element(v.begin(), v.end()), 0.5);  // exactly
    EXPECT_GE(*std::min_element(v.begin(), v.end()), 0.0);
    const double mx = *std::max_element(raw.begin(), raw.end());
    for (std::size_t i = 0; i < v.size(); ++i) EXPECT_DOUBLE_EQ(v[i], raw[i] / (2 * mx));
    // All-zero input: an empty scan, or returns beyond every window.
    layer.rates(Scan{}, v);
    for (double x : v) EXPECT_EQ(x, 0.0);
    layer.rates(Scan{{100.0, 0.0, 0.0}}, v);
    for (double x : v) EXPECT_EQ(x, 0.0);
    // none and fixed.
    BvcParams p = m.bvc;
    p.normalization = BvcNormalization::none;
    BoundaryVectorLayer(p).rates(scan, v);
    for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i], raw[i]);
    p.normalization = BvcNormalization::fixed;
    p.norm_constant = 40.0;
    BoundaryVectorLayer(p).rates(scan, v);
    for (std::size_t i = 0; i < v.size(); ++i) EXPECT_DOUBLE_EQ(v[i], raw[i] / 40.0);
}

TEST(BoundaryVectorLayer, InputHygiene) {
    const BoundaryVectorLayer layer(model_preset("3d-0.1").bvc);
    std::vector<double> a(layer.n_cells()), b(layer.n_cells());
    // NaN and +inf ranges are "no return": skipped, never NaN rates.
    layer.rates(Scan{{3.0, 0.2, 0.0}, {NAN, 0.1, 0.0}, {INFINITY, 1.0, 0.1}}, a);
    layer.rates(Scan{{3.0, 0.2, 0.0}}, b);
    EXPECT_EQ(a, b);
    layer.rates(Scan{{NAN, 0.1, 0.0}}, a);
    for (double x : a) EXPECT_EQ(x, 0.0);
    // Negative or -inf ranges and non-finite angles are errors that name the return.
    try {
        layer.rates(Scan{{3.0, 0.2, 0.0}, {-1.0, 0.0, 0.0}}, a);
        ADD_FAILURE();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("return 1: negative range"), std::string::npos) << e.what();
    }
    EXPECT_THROW(layer.rates(Scan{{-INFINITY, 0.0, 0.0}}, a), InputError);
    EXPECT_THROW(layer.rates(Scan{{1.0, NAN, 0.0}}, a), InputError);
    EXPECT_THROW(layer.rates(Scan{{1.0, 0.0, INFINITY}}, a), InputError);
    std::vector<double> small(3);
    EXPECT_THROW(layer.rates(Scan{}, small), InputError);
}

TEST(BoundaryVectorLayer, RejectsImpossibleParameters) {
    auto bad = [](auto edit) {
        BvcParams p;
        edit(p);
        EXPECT_THROW(BoundaryVectorLayer{p}, InputError);
    };
    bad([](BvcParams& p) { p.n_dir = 0; });
    bad([](BvcParams& p) { p.n_per_axis = 0; });
    bad([](BvcParams& p) { p.sigma_r = 0; });
    bad([](BvcParams& p) { p.sigma_phi = -1; });
    bad([](BvcParams& p) { p.max_dist = NAN; });
    bad([](BvcParams& p) { p.elevations = {0.1, 3.0}; });
    bad([](BvcParams& p) {
        p.normalization = BvcNormalization::fixed;
        p.norm_constant = 0;
    });
    bad([](BvcParams& p) {
        p.reading = BvcReading::nearest_beam;
        p.elevations = {0.0};
    });
}

TEST(ModelPresets, TableOne) {
    for (const auto& name : {"2d", "3d-0.1", "3d-0.2", "3d-3l", "2d-8beam"}) {
        const ModelSpec m = model_preset(name);
        EXPECT_EQ(m.bvc.n_cells(), 960) << name;
        EXPECT_EQ(m.place.n_place, 250);
        EXPECT_EQ(m.bvc.n_dir, 8);
        EXPECT_EQ(m.bvc.max_dist, std::string(name) == "2d-8beam" ? 11.9 : 12.0);
    }
    EXPECT_EQ(model_preset("2d").sensor.name, "horizontal");
    EXPECT_EQ(model_preset("3d-3l").sensor.name, "spherical");
    EXPECT_EQ(model_preset("3d-3l").bvc.elevations, (std::vector<double>{0.0, 0.1, 0.2}));
    EXPECT_NEAR(model_preset("2d-8beam").bvc.spacing(), 0.1, 1e-15);
    EXPECT_THROW(model_preset("4d"), InputError);
}

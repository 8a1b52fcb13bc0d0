// Analysis stage (docs/model-reference.md#analysis): hexagonal bins by matplotlib's rule, numpy's percentile, DBSCAN by
// scikit-learn's neighborhood rule, SAI against a double loop, decoding of a synthetic population.
// The exact comparisons against matplotlib, numpy and scikit-learn themselves are in
// test/python/test_analysis.py; here the rules are checked on cases worked out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "bvc3d/analysis/trial_metrics.hpp"
#include "bvc3d/core/error.hpp"

using namespace bvc3d;
using namespace bvc3d::analysis;

namespace {

// A grid whose lattice units are meters, so index coordinates are the coordinates themselves.
HexGrid unit_grid(int nx, int ny) {
    HexGrid g;
    g.nx = nx;
    g.ny = ny;
    g.sx = g.sy = 1.0;
    return g;
}

Centers to_centers(const std::vector<std::array<double, 2>>& p) {
    Centers c(static_cast<Eigen::Index>(p.size()), 2);
    for (std::size_t i = 0; i < p.size(); ++i) c.row(static_cast<Eigen::Index>(i)) << p[i][0], p[i][1];
    return c;
}

}  // namespace

TEST(AnalysisHexbin, NonsingularFollowsMatplotlib) {
    EXPECT_EQ(nonsingular(0.0, 0.0, 0.1), (std::array<double, 2>{-0.1, 0.1}));
    EXPECT_EQ(nonsingular(5.0, 5.0, 0.1), (std::array<double, 2>{4.5, 5.5}));
    EXPECT_EQ(nonsingular(1.0, 2.0, 0.1), (std::array<double, 2>{1.0, 2.0}));
    EXPECT_EQ(nonsingular(2.0, 1.0, 0.1), (std::array<double, 2>{1.0, 2.0}));
    EXPECT_EQ(nonsingular(1e-300, 1e-300, 0.1), (std::array<double, 2>{-0.1, 0.1}));
}

TEST(AnalysisHexbin, GridFromExtentPadsXOnly) {
    const std::vector<double> x{1.0}, y{1.0};
    const HexGrid g = HexGrid::fit(x, y, 50, Extent{0, 10, 0, 10});
    EXPECT_EQ(g.nx, 50);
    EXPECT_EQ(g.ny, 28);  // int(50 / sqrt(3))
    EXPECT_DOUBLE_EQ(g.xmin, -1e-8);
    EXPECT_DOUBLE_EQ(g.sx, (10 + 2e-8) / 50);
    EXPECT_EQ(g.ymin, 0.0);
    EXPECT_EQ(g.sy, 10.0 / 28);
    EXPECT_EQ(g.size(), 51 * 29 + 50 * 28);
    EXPECT_DOUBLE_EQ(g.bin_area(), 0.5 * g.sx * g.sy);
}

TEST(AnalysisHexbin, BinRuleRoundingTiesAndEdges) {
    const HexGrid g = unit_grid(4, 2);  // lattice 1: 5 × 3 centers, lattice 2 starts at 15
    EXPECT_EQ(g.bin_of(0.0, 0.0), 0);
    EXPECT_EQ(g.bin_of(2.0, 1.0), 2 * 3 + 1);
    EXPECT_EQ(g.bin_of(0.5, 0.5), 15);     // a lattice-2 center
    EXPECT_EQ(g.bin_of(0.25, 0.25), 15);   // d1 == d2: lattice 2 wins
    EXPECT_EQ(g.bin_of(0.2, 0.25), 0);     // d1 < d2
    EXPECT_EQ(g.bin_of(0.5, 0.0), 0);      // numpy.round(0.5) = 0 (half to even)
    EXPECT_EQ(g.bin_of(1.5, 0.0), 2 * 3);  // round(1.5) = 2
    EXPECT_EQ(g.bin_of(2.5, 0.0), 2 * 3);  // round(2.5) = 2
    EXPECT_EQ(g.bin_of(-0.6, 0.0), -1);    // outside lattice 1
    EXPECT_EQ(g.bin_of(-0.4, 0.5), -1);    // nearest is lattice 2's column -1: dropped, not lattice 1
    EXPECT_EQ(g.bin_of(3.5, 1.5), 15 + 3 * 2 + 1);
    EXPECT_EQ(g.bin_of(4.1, 1.9), 4 * 3 + 2);  // lattice-1 corner (4, 2)
    EXPECT_EQ(g.bin_of(4.4, 1.6), -1);         // nearest is lattice 2's column 4, which does not exist
    EXPECT_EQ(g.center(6), (std::array<double, 2>{2.0, 0.0}));
    EXPECT_EQ(g.center(15), (std::array<double, 2>{0.5, 0.5}));
    EXPECT_EQ(g.center(15 + 3 * 2 + 1), (std::array<double, 2>{3.5, 1.5}));
}

TEST(AnalysisHexbin, VisitedBinsInGridOrderWithMeans) {
    const HexGrid g = unit_grid(4, 2);
    const std::vector<double> x{3.5, 0.0, 0.1, 9.0, 2.0}, y{1.5, 0.0, 0.1, 9.0, 1.0};
    const HexBins b = bin_samples(g, x, y);
    ASSERT_EQ(b.ids, (std::vector<int>{0, 7, 22}));
    EXPECT_EQ(b.counts, (std::vector<std::int64_t>{2, 1, 1}));
    EXPECT_EQ(b.sample_bin, (std::vector<int>{2, 0, 0, -1, 1}));
    EXPECT_EQ(b.centers(2, 0), 3.5);
    RowMatrixXf v(5, 2);
    v << 1, 10, 2, 20, 4, 40, 100, 100, 8, 80;
    const RowMatrixXd m = bin_means<float>(b, v);
    EXPECT_EQ(m(0, 0), 3.0);
    EXPECT_EQ(m(0, 1), 30.0);
    EXPECT_EQ(m(1, 1), 80.0);
    EXPECT_EQ(m(2, 0), 1.0);
}

TEST(AnalysisHexbin, DefaultExtentCoversEveryPoint) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-5, 5);
    std::vector<double> x(5000), y(5000);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = u(rng), y[i] = u(rng);
    const HexBins b = hexbin(x, y);
    std::int64_t total = 0;
    for (const auto c : b.counts) total += c;
    EXPECT_EQ(total, 5000);
    for (const int s : b.sample_bin) EXPECT_GE(s, 0);
}

TEST(AnalysisRateMaps, PercentileLinear) {
    std::vector<double> v{4, 1, 3, 2};
    EXPECT_DOUBLE_EQ(percentile_linear(v, 10), 1.3);
    EXPECT_DOUBLE_EQ(percentile_linear(v, 50), 2.5);
    EXPECT_EQ(percentile_linear(v, 0), 1.0);
    EXPECT_EQ(percentile_linear(v, 100), 4.0);
    std::vector<double> one{7};
    EXPECT_EQ(percentile_linear(one, 10), 7.0);
}

TEST(AnalysisRateMaps, ThresholdThenNormalise) {
    RowMatrixXd m(5, 3);
    m << 0, 1, 0,  //
        0, 2, 0,   //
        0, 3, 0,   //
        2, 4, 0,   //
        4, 5, 0;
    threshold_and_normalize(m, 0.1);
    EXPECT_EQ(m(3, 0), 0.5);  // the 10 % quantile of a mostly silent cell is 0: nothing removed
    EXPECT_EQ(m(4, 0), 1.0);
    EXPECT_EQ(m(0, 1), 0.0);  // 1 < 1.4
    EXPECT_EQ(m(1, 1), 0.4);
    EXPECT_EQ(m.col(2).cwiseAbs().maxCoeff(), 0.0);  // silent cell: zeros, not NaN
    RowMatrixXd m2 = RowMatrixXd::Ones(3, 1);
    EXPECT_THROW(threshold_and_normalize(m2, 1.5), InputError);
}

TEST(AnalysisModality, ClustersChainsAndNoise) {
    std::vector<std::array<double, 2>> p;
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 5; ++j) {
            p.push_back({0.3 * i, 0.3 * j});
            p.push_back({6 + 0.3 * i, 0.3 * j});
        }
    EXPECT_EQ(dbscan_cluster_count(to_centers(p)), 2);
    EXPECT_EQ(dbscan_cluster_count(to_centers(p), {1.0, 51}), 0);
    std::vector<std::array<double, 2>> chain;
    for (int i = 0; i < 30; ++i) chain.push_back({0.9 * i, 1.0});
    EXPECT_EQ(dbscan_cluster_count(to_centers(chain), {1.0, 3}), 1);  // left, self, right
    EXPECT_EQ(dbscan_cluster_count(to_centers(chain), {1.0, 4}), 0);
    chain[15][1] = 50;  // break the chain
    EXPECT_EQ(dbscan_cluster_count(to_centers(chain), {1.0, 3}), 2);
    EXPECT_EQ(dbscan_cluster_count(Centers(0, 2)), 0);
}

TEST(AnalysisModality, KdTreeNodeTestAcceptsPointsTheDistanceTestRejects) {
    // q is at dx² + dy² = 1 + 2^-52 from p: rejected by dx² + dy² <= eps², but in a 12-point set
    // scikit-learn's KD-tree sees the whole box within pow(1 + 2^-52, 0.5) == 1 <= eps of p.
    std::vector<std::array<double, 2>> pts{{0, 0}, {1, std::ldexp(1.0, -26)}};
    for (int i = 0; i < 10; ++i) pts.push_back({0.1 + 0.07 * i, std::ldexp(1.0, -28)});
    const auto contains = [](const Neighborhoods& nb, int i, int j) {
        for (int k = nb.offsets[static_cast<std::size_t>(i)]; k < nb.offsets[static_cast<std::size_t>(i) + 1]; ++k)
            if (nb.indices[static_cast<std::size_t>(k)] == j) return true;
        return false;
    };
    const Neighborhoods tree = sklearn_radius_neighbors(to_centers(pts), 1.0);
    EXPECT_TRUE(contains(tree, 0, 1));
    EXPECT_EQ(tree.offsets[1], 12);
    pts.pop_back();  // 11 points: brute force, which computes 1 + 2^-52 - ... and rejects q
    const Neighborhoods brute = sklearn_radius_neighbors(to_centers(pts), 1.0);
    EXPECT_FALSE(contains(brute, 0, 1));
}

TEST(AnalysisModality, SummaryFigures) {
    const std::vector<int> mi{0, 1, 2, 3, 0, 1};
    const ModalitySummary s = summarize_modality(mi);
    EXPECT_DOUBLE_EQ(s.frac_active, 4.0 / 6);
    EXPECT_DOUBLE_EQ(s.mean_mi_active, 7.0 / 4);
    EXPECT_DOUBLE_EQ(s.frac_multimodal, 2.0 / 6);
    EXPECT_TRUE(std::isnan(summarize_modality(std::vector<int>{0, 0}).mean_mi_active));
}

TEST(AnalysisAliasing, MatchesDoubleLoop) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(-5, 5), r(0, 1);
    const int n = 300, cells = 9;
    Centers c(n, 2);
    RowMatrixXd m(n, cells);
    for (int i = 0; i < n; ++i) {
        c.row(i) << u(rng), u(rng);
        for (int k = 0; k < cells; ++k) m(i, k) = r(rng) < 0.3 ? r(rng) : 0.0;
    }
    m.row(7).setZero();
    const AliasingResult res = spatial_aliasing(c, m, 2.0);
    double total = 0;
    for (int i = 0; i < n; ++i) {
        double s = 0;
        for (int j = 0; j < n; ++j) {
            const double dx = c(i, 0) - c(j, 0), dy = c(i, 1) - c(j, 1);
            const double ni = m.row(i).norm(), nj = m.row(j).norm();
            if (j != i && std::sqrt(dx * dx + dy * dy) > 2.0 && ni > 0 && nj > 0)
                s += m.row(i).dot(m.row(j)) / (ni * nj);
        }
        EXPECT_NEAR(res.sai(i), s / n, 1e-12);
        total += s / n;
    }
    EXPECT_NEAR(res.msai, total / n, 1e-12);
    EXPECT_EQ(res.sai(7), 0.0);
    // A fixed number of bins (the authors' 2662): SAI_i = Σ cos / 2662, MSAI = Σ_i Σ_j cos / 2662².
    const AliasingResult fixed = spatial_aliasing(c, m, 2.0, 2662);
    for (int i = 0; i < n; ++i) EXPECT_NEAR(fixed.sai(i), res.sai(i) * n / 2662, 1e-12);
    EXPECT_NEAR(fixed.msai, total * n / (2662.0 * 2662.0), 1e-12);
}

TEST(AnalysisDecoding, GaussianPlaceFieldsDecodeWell) {
    // A sweep over the arena and one Gaussian field per cell on a 10 × 10 grid of centers.
    std::mt19937_64 rng(9);
    std::uniform_real_distribution<double> u(-5, 5);
    const int n = 20000, cells = 100;
    std::vector<double> x(n), y(n);
    RowMatrixXf rates(n, cells);
    for (int i = 0; i < n; ++i) {
        x[static_cast<std::size_t>(i)] = u(rng), y[static_cast<std::size_t>(i)] = u(rng);
        for (int k = 0; k < cells; ++k) {
            const double cx = -4.5 + k % 10, cy = -4.5 + k / 10;
            const double d2 =
                std::pow(x[static_cast<std::size_t>(i)] - cx, 2) + std::pow(y[static_cast<std::size_t>(i)] - cy, 2);
            const double v = std::exp(-d2 / (2 * 0.8 * 0.8));
            rates(i, k) = v < 0.05 ? 0.f : static_cast<float>(v);
        }
    }
    for (const auto templates : {DecodingTemplates::rate_maps, DecodingTemplates::means}) {
        SCOPED_TRACE(decoding_templates_name(templates));
        const DecodingResult d = decoding_error<float>(x, y, rates, {50, 0.1, {}, templates});
        EXPECT_EQ(d.n_decoded + d.n_undecoded, static_cast<std::size_t>(n - n / 2));
        EXPECT_EQ(d.n_undecoded, 0u);
        EXPECT_LT(d.median_m, 0.35);
        EXPECT_LT(d.mean_m, 0.5);
    }
}

TEST(AnalysisDecoding, DefaultTemplatesAreTheNormalizedRateMaps) {
    // First half: x = 0 with rates (10, 1), x = 1 with (1, 0.6), x = 2 silent (three bins; the 10 %
    // quantile of each cell is then below its smaller rate and removes nothing). Raw means are the
    // templates (10, 1) and (1, 0.6); the rate maps, normalized per cell, are (1, 1) and
    // (0.1, 0.6). Second half, cosines with x = 0's and x = 1's template:
    //   (10, 1) at x = 0:  means 1.00 / 0.90, maps 0.77 / 0.26: x = 0 either way;
    //   (1, 1) at x = 1:   means 0.77 / 0.97, maps 1.00 / 0.81: the maps decode it 1 m off;
    //   (0.1, 1) at x = 1: means 0.20 / 0.60, maps 0.77 / 1.00: x = 1 either way;
    //   (0, 0) at x = 2:   not decoded.
    // At quantile 0.9 only each cell's largest value survives: x = 1's map is all zero and the third
    // sample goes to x = 0 as well.
    const std::vector<double> x{0, 1, 2, 2, 0, 1, 1, 2}, y(8, 0.0);
    RowMatrixXd r(8, 2);
    r << 10, 1, 1, 0.6, 0, 0, 0, 0,  // first half
        10, 1, 1, 1, 0.1, 1, 0, 0;   // second half
    DecodingParams params;
    params.gridsize = 4;  // bin centers at x = 0, 1, 2 (to 1e-9)
    const DecodingResult by_default = decoding_error<double>(x, y, r, params);
    params.templates = DecodingTemplates::means;
    const DecodingResult means = decoding_error<double>(x, y, r, params);
    params.templates = DecodingTemplates::rate_maps;
    params.quantile = 0.9;
    const DecodingResult q90 = decoding_error<double>(x, y, r, params);
    for (const DecodingResult* d : {&by_default, &means, &q90}) {
        EXPECT_EQ(d->n_decoded, 3u);
        EXPECT_EQ(d->n_undecoded, 1u);
    }
    EXPECT_NEAR(by_default.mean_m, 1.0 / 3, 1e-8);
    EXPECT_NEAR(by_default.median_m, 0.0, 1e-8);
    EXPECT_NEAR(means.mean_m, 0.0, 1e-8);
    EXPECT_NEAR(q90.mean_m, 2.0 / 3, 1e-8);
    EXPECT_NEAR(q90.median_m, 1.0, 1e-8);
    // The grid overload (analyze_trial's) is the same decoder, and analyze_trial passes its quantile.
    const HexGrid g = HexGrid::fit(x, y, 4);
    EXPECT_EQ(decoding_error<double>(g, positions_2d(x, y), r, DecodingTemplates::rate_maps, 0.1).mean_m,
              by_default.mean_m);
    AnalysisParams ap;
    ap.gridsize = 4;
    EXPECT_EQ(analyze_trial<double>(x, y, r, ap).decoding.mean_m, by_default.mean_m);
    ap.quantile = 0.9;
    EXPECT_EQ(analyze_trial<double>(x, y, r, ap).decoding.mean_m, q90.mean_m);
    ap.decoding_templates = DecodingTemplates::means;
    EXPECT_EQ(analyze_trial<double>(x, y, r, ap).decoding.mean_m, means.mean_m);
}

TEST(AnalysisTrial, AllMetricsOfOneTrial) {
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> u(-5, 5);
    const int n = 20000, cells = 20;  // ~7 samples per bin: every bin visited
    std::vector<double> x(n), y(n);
    RowMatrixXf rates = RowMatrixXf::Zero(n, cells);
    for (int i = 0; i < n; ++i) {
        x[static_cast<std::size_t>(i)] = u(rng), y[static_cast<std::size_t>(i)] = u(rng);
        for (int k = 0; k < cells; ++k)
            if (std::abs(x[static_cast<std::size_t>(i)] - (k % 5) * 2 + 4) < 0.8 &&
                std::abs(y[static_cast<std::size_t>(i)] - (k / 5) * 2 + 3) < 0.8)
                rates(i, k) = 1.f;
    }
    const TrialMetrics m = analyze_trial<float>(x, y, rates);
    const int bins = m.maps.bins.size();
    EXPECT_GT(bins, 1000);
    EXPECT_EQ(m.maps.map.rows(), bins);
    EXPECT_EQ(m.aliasing.sai.size(), bins);
    ASSERT_EQ(m.modality.size(), static_cast<std::size_t>(cells));
    for (const int mi : m.modality) EXPECT_EQ(mi, 1);  // one square field per cell
    EXPECT_EQ(m.modality_summary.frac_active, 1.0);
    for (const double a : m.cells.field_area) EXPECT_NEAR(a, 1.6 * 1.6, 0.4);
    EXPECT_GT(m.decoding.n_decoded, 0u);
}

TEST(AnalysisTrial, ZeroAndOneSampleDoNotThrow) {
    const std::vector<double> none;
    const TrialMetrics m0 = analyze_trial<float>(none, none, RowMatrixXf(0, 3));
    EXPECT_EQ(m0.maps.bins.size(), 0);
    EXPECT_EQ(m0.maps.map.rows(), 0);
    EXPECT_EQ(m0.maps.map.cols(), 3);
    EXPECT_EQ(m0.modality, (std::vector<int>{0, 0, 0}));
    EXPECT_EQ(m0.modality_summary.frac_active, 0.0);
    EXPECT_TRUE(std::isnan(m0.modality_summary.mean_mi_active));
    EXPECT_TRUE(std::isnan(m0.aliasing.msai));
    EXPECT_TRUE(std::isnan(m0.decoding.median_m));
    EXPECT_TRUE(std::isnan(m0.decoding.mean_m));
    EXPECT_EQ(m0.decoding.n_decoded, 0u);
    EXPECT_EQ(m0.decoding.n_undecoded, 0u);
    EXPECT_EQ(m0.cells.peak_rate.size(), 3u);

    const std::vector<double> x{2.0}, y{-1.0};
    RowMatrixXf r = RowMatrixXf::Zero(1, 3);
    r(0, 2) = 0.5f;
    const TrialMetrics m1 = analyze_trial<float>(x, y, r);
    ASSERT_EQ(m1.maps.bins.size(), 1);  // matplotlib: one bin, the grid expanded around the point
    EXPECT_EQ(m1.maps.map(0, 2), 1.0);
    EXPECT_EQ(m1.maps.map(0, 0), 0.0);
    EXPECT_EQ(m1.modality, (std::vector<int>{0, 0, 0}));
    EXPECT_EQ(m1.aliasing.msai, 0.0);
    EXPECT_TRUE(std::isnan(m1.decoding.median_m));
    EXPECT_EQ(m1.decoding.n_decoded, 0u);
    EXPECT_EQ(m1.decoding.n_undecoded, 1u);  // the second half of 1 sample is that sample
    EXPECT_DOUBLE_EQ(m1.cells.peak_rate[2], 0.5);
    EXPECT_THROW(decoding_error<float>(x, y, r), InputError);  // called directly, decoding still needs 2
}

TEST(AnalysisInput, BadInputThrows) {
    const std::vector<double> x{0, 1, 2}, y{0, 1}, y3{0, 1, NAN};
    EXPECT_THROW(hexbin(x, y), InputError);
    EXPECT_THROW(hexbin(x, y3), InputError);
    EXPECT_THROW(hexbin(x, x, 1), InputError);
    EXPECT_THROW(hexbin(x, x, 50, Extent{1, 0, 0, 1}), InputError);
    const Centers c = Centers::Zero(3, 2);
    EXPECT_THROW(dbscan_cluster_count(c, {0.0, 5}), InputError);
    EXPECT_THROW(dbscan_cluster_count(c, {1.0, 0}), InputError);
    EXPECT_THROW(spatial_aliasing(c, RowMatrixXd::Ones(2, 2), 2.0), InputError);
    EXPECT_THROW(spatial_aliasing(c, RowMatrixXd::Ones(3, 2), -1.0), InputError);
    const RowMatrixXd r = RowMatrixXd::Ones(3, 2);
    EXPECT_THROW(rate_maps<double>(x, x, r, {50, -0.5, {}}), InputError);
    EXPECT_THROW(decoding_error<double>(x, x, RowMatrixXd::Ones(2, 2)), InputError);
    EXPECT_THROW(decoding_error<double>(x, x, r, {50, 1.5, {}, DecodingTemplates::rate_maps}), InputError);
    EXPECT_THROW(parse_decoding_templates("maps"), InputError);
    EXPECT_EQ(parse_decoding_templates("means"), DecodingTemplates::means);
    EXPECT_EQ(parse_decoding_templates(decoding_templates_name(DecodingTemplates::rate_maps)),
              DecodingTemplates::rate_maps);
}

// Beam layout of the scanners (docs/model-reference.md#sensors) and the allocentric return convention
// (docs/model-reference.md#conventions).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/sensor/lidar.hpp"

using namespace bvc3d;

namespace {
// A world that every beam hits: a closed box, big enough that ranges are easy to predict.
World box_world() {
    WorldDescription w;
    w.name = "box";
    w.mesh = box_mesh(Vec3(20, 20, 20));
    w.walkable = Polygon2::rectangle(-10, -10, 10, 10);
    w.start.points = {Vec2(0, 0)};
    return World(w);
}
}  // namespace

// wrap_pi takes a shortcut for angles one turn out; it must give the bits std::remainder gives.
TEST(Angles, WrapPiOneTurnOutIsExactlyTheRemainder) {
    auto by_remainder = [](double a) {
        const double w = std::remainder(a, two_pi);
        return w <= -pi ? w + two_pi : w;
    };
    std::vector<double> angles;
    for (double edge : {pi, -pi, 3 * pi, -3 * pi, 2 * pi, -2 * pi})
        for (double a = edge, up = edge, k = 0; k < 4; ++k) {
            angles.push_back(a = std::nextafter(a, -INFINITY));
            angles.push_back(up = std::nextafter(up, INFINITY));
            angles.push_back(edge);
        }
    std::mt19937_64 gen(3);
    std::uniform_real_distribution<double> u(-4 * pi, 4 * pi);
    for (int i = 0; i < 200000; ++i) angles.push_back(u(gen));
    for (double a : angles) {
        if (a > -pi && a <= pi) continue;
        const double fast = wrap_pi(a), slow = by_remainder(a);
        ASSERT_EQ(std::memcmp(&fast, &slow, sizeof fast), 0) << std::hexfloat << a << ": " << fast << " vs " << slow;
    }
}

TEST(BeamLayout, HorizontalScanner) {
    const auto s = LidarSpec::horizontal();
    EXPECT_EQ(s.beam_count(), 720u);
    EXPECT_EQ(s.elevations, std::vector<double>{0.0});
    EXPECT_DOUBLE_EQ(s.height, 0.08);
    EXPECT_DOUBLE_EQ(s.max_range, 20.0);
    const Scan scan = Lidar(s).scan(box_world(), Pose::on_floor(0, 0, 0));
    ASSERT_EQ(scan.size(), 720u);
    for (int k : {0, 1, 90, 359, 360, 719}) {
        EXPECT_NEAR(scan[k].azimuth, wrap_pi(deg_to_rad(0.5 * k)), 1e-15) << k;
        EXPECT_EQ(scan[k].elevation, 0.0);
    }
    EXPECT_NEAR(scan[0].range, 10.0, 1e-9);
    EXPECT_NEAR(scan[90].range, 10.0 / std::cos(deg_to_rad(45.0)), 1e-9);  // the corner
}

TEST(BeamLayout, SphericalScannerKeepsTheUpperHalf) {
    const auto upper = LidarSpec::spherical(true);
    const auto all = LidarSpec::spherical(false);
    EXPECT_EQ(all.elevations.size(), 90u);
    EXPECT_EQ(all.azimuth_count, 180);
    EXPECT_EQ(upper.elevations.size(), 45u);
    EXPECT_EQ(upper.beam_count(), 45u * 180u);
    EXPECT_DOUBLE_EQ(upper.height, 0.18);
    // Row i at elevation pi/2 - (i + 0.5)·pi/90: row 0 at 89°, row 44 at +1°, row 45 at -1°.
    EXPECT_NEAR(rad_to_deg(all.elevations[0]), 89.0, 1e-12);
    EXPECT_NEAR(rad_to_deg(all.elevations[44]), 1.0, 1e-12);
    EXPECT_NEAR(rad_to_deg(all.elevations[45]), -1.0, 1e-12);
    EXPECT_NEAR(rad_to_deg(all.elevations[89]), -89.0, 1e-12);
    for (int i = 0; i < 45; ++i) {
        EXPECT_EQ(upper.elevations[i], all.elevations[i]);
        EXPECT_GT(upper.elevations[i], 0.0);
    }

    const Scan scan = Lidar(upper).scan(box_world(), Pose::on_floor(0, 0, 0));
    ASSERT_EQ(scan.size(), 8100u);
    // Beam index = row·180 + column; column j at azimuth 2j degrees.
    const auto& b = scan[44 * 180 + 45];
    EXPECT_NEAR(rad_to_deg(b.elevation), 1.0, 1e-12);
    EXPECT_NEAR(rad_to_deg(b.azimuth), 90.0, 1e-12);
    EXPECT_NEAR(b.range, 10.0 / std::cos(deg_to_rad(1.0)), 1e-9);
    const auto& top = scan[0];
    EXPECT_NEAR(top.range, (10.0 - 0.18) / std::sin(deg_to_rad(89.0)), 1e-9);
}

TEST(BeamLayout, AzimuthsAreAllocentricAndTurnWithHeading) {
    const World w = box_world();
    const Lidar lidar(LidarSpec::horizontal());
    for (double heading : {0.0, 0.7, -2.0, pi, 3.0 * pi}) {
        const Scan scan = lidar.scan(w, Pose::on_floor(1.0, -2.0, heading));
        ASSERT_EQ(scan.size(), 720u);
        for (int k : {0, 100, 500}) {
            const double expected = wrap_pi(heading + deg_to_rad(0.5 * k));
            EXPECT_NEAR(std::abs(wrap_pi(scan[k].azimuth - expected)), 0.0, 1e-12);
            EXPECT_GT(scan[k].azimuth, -pi);
            EXPECT_LE(scan[k].azimuth, pi);
        }
        // Beam 0 points along the heading: the range is that of a ray from (1, -2) along it.
        const double c = std::cos(heading), s = std::sin(heading);
        const double tx = c > 1e-12 ? (10 - 1.0) / c : c < -1e-12 ? (-10 - 1.0) / c : INFINITY;
        const double ty = s > 1e-12 ? (10 + 2.0) / s : s < -1e-12 ? (-10 + 2.0) / s : INFINITY;
        EXPECT_NEAR(scan[0].range, std::min(tx, ty), 1e-9) << heading;
    }
    // The same allocentric direction gives the same range whatever the heading.
    const Scan a = lidar.scan(w, Pose::on_floor(1.0, -2.0, 0.0));
    const Scan b = lidar.scan(w, Pose::on_floor(1.0, -2.0, deg_to_rad(90.0)));
    EXPECT_NEAR(a[180].range, b[0].range, 1e-12);
    EXPECT_NEAR(a[180].azimuth, b[0].azimuth, 1e-12);
}

TEST(BeamLayout, GenericBeamTable) {
    LidarSpec s;
    s.name = "hdl64-like";
    s.elevations.clear();
    for (int i = 0; i < 64; ++i) s.elevations.push_back(deg_to_rad(2.0 - i * 26.8 / 63));
    s.azimuth_count = 1024;
    s.height = 0.3;
    const Scan scan = Lidar(s).scan(box_world(), Pose::on_floor(0, 0, 0.5));
    ASSERT_EQ(scan.size(), 64u * 1024u);
    EXPECT_NEAR(scan[5 * 1024 + 256].elevation, s.elevations[5], 0);
    EXPECT_NEAR(scan[5 * 1024 + 256].azimuth, wrap_pi(0.5 + pi / 2), 1e-12);
}

TEST(BeamLayout, MaxRangeDropsFarBeamsAndRowMaskSelectsRows) {
    LidarSpec s = LidarSpec::spherical();
    s.max_range = 10.5;
    const World w = box_world();
    const Scan scan = Lidar(s).scan(w, Pose::on_floor(0, 0, 0));
    for (const auto& r : scan) EXPECT_LE(r.range, 10.5);
    EXPECT_LT(scan.size(), 8100u);
    std::vector<char> rows(45, 0);
    rows[44] = 1;
    Scan one_row;
    Lidar(LidarSpec::spherical()).scan(w, Pose::on_floor(0, 0, 0), one_row, {}, rows);
    ASSERT_EQ(one_row.size(), 180u);
    for (const auto& r : one_row) EXPECT_NEAR(rad_to_deg(r.elevation), 1.0, 1e-12);
}

TEST(SensorNoise, SeededNoiseAndDropout) {
    LidarSpec s = LidarSpec::horizontal();
    s.range_noise_sd = 0.05;
    s.dropout = 0.2;
    const World w = box_world();
    const Lidar lidar(s), clean(LidarSpec::horizontal());
    const Scan a = lidar.scan(w, Pose::on_floor(0, 0, 0), NoiseKey{7, 3});
    const Scan b = lidar.scan(w, Pose::on_floor(0, 0, 0), NoiseKey{7, 3});
    const Scan c = lidar.scan(w, Pose::on_floor(0, 0, 0), NoiseKey{7, 4});
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].range, b[i].range);
    EXPECT_NE(a.size() == c.size() && a[0].range == c[0].range, true);
    // About 20 % of the beams dropped, and range errors with sd ≈ 0.05 m.
    EXPECT_NEAR(static_cast<double>(a.size()) / 720.0, 0.8, 0.06);
    const Scan exact = clean.scan(w, Pose::on_floor(0, 0, 0));
    double sum = 0, sum2 = 0;
    int n = 0;
    for (const auto& r : a) {
        const auto k = static_cast<std::size_t>(std::lround(rad_to_deg(wrap_pi(r.azimuth)) * 2 + 720)) % 720;
        const double e = r.range - exact[k].range;
        sum += e;
        sum2 += e * e;
        ++n;
    }
    EXPECT_NEAR(sum / n, 0.0, 0.01);
    EXPECT_NEAR(std::sqrt(sum2 / n), 0.05, 0.008);
}

TEST(SensorSpec, RejectsImpossibleValues) {
    LidarSpec s = LidarSpec::horizontal();
    s.max_range = -1;
    EXPECT_THROW(Lidar{s}, InputError);
    s = LidarSpec::horizontal();
    s.dropout = 1.0;
    EXPECT_THROW(Lidar{s}, InputError);
    s = LidarSpec::horizontal();
    s.elevations = {};
    EXPECT_THROW(Lidar{s}, InputError);
    s = LidarSpec::horizontal();
    s.azimuth_count = 0;
    EXPECT_THROW(Lidar{s}, InputError);
}

TEST(SensorSpec, RejectsPosesOutsideAnyWorld) {
    const World w = box_world();
    const Lidar lidar(LidarSpec::horizontal());
    EXPECT_THROW(lidar.scan(w, Pose::on_floor(NAN, 0, 0)), InputError);
    EXPECT_THROW(lidar.scan(w, Pose::on_floor(0, 0, INFINITY)), InputError);
    EXPECT_THROW(lidar.scan(w, Pose::on_floor(1e30, 0, 0)), InputError);
    EXPECT_NO_THROW(lidar.scan(w, Pose::on_floor(0, 0, 100.0)));  // a heading of many turns is fine
}

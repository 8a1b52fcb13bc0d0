// Recordings replayed through models: the preprocessing of recorded scans against its definition,
// sources behind the ReturnSource seam, trials without a world, the export -> replay round trip
// against the simulator's own rates, gravity alignment of tilted sensors, voxel maps, and the
// writers' all-or-nothing folders.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "../support/temp_dir.hpp"
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/analysis/localization.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/core/angles.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/experiment/replay.hpp"
#include "bvc3d/recording/pcd.hpp"
#include "bvc3d/recording/recording.hpp"
#include "bvc3d/recording/voxel_map.hpp"
#include "bvc3d/sensor/recorded_returns.hpp"

using namespace bvc3d;
namespace fs = std::filesystem;

namespace {

using bvc3d::test::TempDir;

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
    std::normal_distribution<double> n(0, 1);
    Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
    return q.normalized().toRotationMatrix();
}

// The returns of SPEC's definition, computed another way: φ from asin(v_z / r), θ from atan2.
struct Expected {
    double r, theta, phi;
};
std::vector<Expected> oracle(const std::vector<double>& xyz, const Eigen::Matrix3d& R, const RecordedReturnParams& p,
                             ReturnSelection s) {
    std::vector<Expected> out;
    for (std::size_t i = 0; i < xyz.size() / 3; ++i) {
        const Vec3 v = R * Vec3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
        const double r = v.norm();
        if (!(r >= p.min_range && r <= p.max_range)) continue;
        const double phi = std::asin(v.z() / r);
        if (s == ReturnSelection::upper_half && phi < 0) continue;
        if (s == ReturnSelection::horizontal_slice && std::abs(phi) > p.slice_half_width) continue;
        out.push_back({r, std::atan2(v.y(), v.x()), phi});
    }
    return out;
}

// A random walk's steps in `world` with the sensor each model reads, exported as a recording.
std::shared_ptr<const recording::Recording> export_walk(const World& world, const std::vector<ModelStep>& steps,
                                                        const LidarSpec& sensor, const fs::path& folder,
                                                        recording::ScanWriteFormat format) {
    const Lidar lidar(sensor);
    std::vector<recording::PointCloud> clouds;
    std::vector<recording::PoseRecord> poses;
    for (std::size_t i = 0; i < steps.size(); ++i) {
        const Scan scan = lidar.scan(world, steps[i].pose);
        recording::PoseRecord pose;
        pose.world_from_sensor = sensor_pose(steps[i].pose, sensor.height);
        pose.time = steps[i].t;
        clouds.push_back(points_from_returns(scan, pose.world_from_sensor.linear()));
        poses.push_back(pose);
    }
    recording::write_recording(folder, clouds, poses, format);
    return std::make_shared<const recording::Recording>(
        recording::open_recording(folder / "scans.txt", folder / "poses.txt"));
}

double max_abs(const std::vector<float>& a) {
    double m = 0;
    for (float v : a) m = std::max(m, static_cast<double>(std::abs(v)));
    return m;
}

}  // namespace

TEST(RecordedReturns, FollowTheDefinitionForEverySelection) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> coord(-25, 25);
    std::vector<double> xyz;
    for (int i = 0; i < 20000; ++i) xyz.push_back(coord(rng));
    std::uniform_real_distribution<double> low(-0.3, 0.3);
    for (int i = 0; i < 2000; ++i) xyz.insert(xyz.end(), {coord(rng), coord(rng), low(rng)});  // near the horizon
    // Points at the range limits and on the horizon, where rounding decides.
    for (double v : {0.3, 0.2999999, 20.0, 20.0000001, 5.0}) xyz.insert(xyz.end(), {v, 0.0, 0.0});
    RecordedReturnParams p;
    for (int trial = 0; trial < 4; ++trial) {
        const Eigen::Matrix3d R = trial == 0 ? Eigen::Matrix3d::Identity() : random_rotation(rng);
        for (const auto s : {ReturnSelection::upper_half, ReturnSelection::all, ReturnSelection::horizontal_slice}) {
            Scan got;
            returns_from_points(xyz, R, p, s, got);
            const auto want = oracle(xyz, R, p, s);
            ASSERT_EQ(got.size(), want.size()) << selection_name(s) << " trial " << trial;
            for (std::size_t i = 0; i < got.size(); ++i) {
                ASSERT_NEAR(got[i].range, want[i].r, 1e-12);
                ASSERT_NEAR(got[i].azimuth, want[i].theta, 1e-12);
                ASSERT_NEAR(got[i].elevation, want[i].phi, 1e-9);  // asin is ill-conditioned near the poles
                ASSERT_GT(got[i].azimuth, -pi);
            }
            if (s == ReturnSelection::horizontal_slice) {
                EXPECT_GT(got.size(), 20u);  // the slice is exercised
            }
        }
    }
}

TEST(RecordedReturns, EachModelGetsItsSelection) {
    EXPECT_EQ(selection_for(model_preset("2d").sensor, true), ReturnSelection::horizontal_slice);
    EXPECT_EQ(selection_for(model_preset("2d-8beam").sensor, true), ReturnSelection::horizontal_slice);
    for (const char* m : {"3d-0.1", "3d-0.2", "3d-3l"})
        EXPECT_EQ(selection_for(model_preset(m).sensor, false), ReturnSelection::upper_half) << m;
    EXPECT_EQ(selection_for(LidarSpec::spherical(false), false), ReturnSelection::all);
    RecordedReturnParams bad;
    bad.min_range = 30;
    EXPECT_THROW(bad.validate(), InputError);
}

TEST(FilteredSource, CastsOnlyWhatItKeepsAndKeepsWhatTheFilterKeeps) {
    const World world = World::cross({.tilt_deg = 45});
    LidarSpec sensor = LidarSpec::spherical(false);  // both halves: the selection decides
    RecordedReturnParams p;
    p.min_range = 1.0;  // drops real returns at this pose
    auto cast = std::make_shared<RayCastSource>(world, sensor, 0);
    for (const auto s : {ReturnSelection::upper_half, ReturnSelection::horizontal_slice}) {
        FilteredSource filtered(cast, p, s);
        for (const Pose& pose : {Pose::on_floor(-3.9, 1.2, 0.3), Pose{-3.9, 1.2, 0.0, 0.3, 0.2, -0.3}}) {
            Scan got, full;
            filtered.returns(0, pose, {}, got);
            cast->returns(0, pose, {}, full);
            filter_returns(full, p, s);
            ASSERT_EQ(got.size(), full.size());
            for (std::size_t i = 0; i < got.size(); ++i) {
                EXPECT_EQ(got[i].range, full[i].range);
                EXPECT_EQ(got[i].elevation, full[i].elevation);
            }
            for (const auto& r : got) EXPECT_GE(r.range, 1.0);
        }
    }
}

TEST(Replay, ExportedScansReplayToTheSimulationsRates) {
    // The whole chain: the simulator's BVC rates on a walk, and the same walk exported as float64
    // PCD scans with poses, read back, preprocessed and replayed: equal within 1e-6 of the peak.
    const World world = World::cross({.tilt_deg = 45});
    std::vector<ModelStep> steps = random_walk(world, 0.02, 3);
    steps.resize(40);
    auto path = std::make_shared<TrajectorySpec>(steps, "walk");
    RecordedReturnParams p;
    p.min_range = 0;  // the simulation keeps returns nearer than 0.3 m at a bump
    for (const char* name : {"2d", "3d-0.2", "3d-3l"}) {
        const ModelSpec model = model_preset(name);
        TrialConfig sim;
        sim.world = WorldSpec{"cross", 45.0, "+x+y"};
        sim.model = model;
        sim.agent = path;
        sim.protocol.explore_hours = 0;
        sim.protocol.sample_hours = (steps.back().t + 1) / 3600;
        sim.protocol.record_bvc = true;
        const GroupResult simulated = run_trial_group({sim});

        TempDir dir;
        const auto rec = export_walk(world, steps, model.sensor, dir / "rec", recording::ScanWriteFormat::pcd_f8);
        const GroupResult replayed = run_replay({replay_trial(recorded_source(rec, p), model, false)});
        const auto& a = simulated.models[0].bvc;
        const auto& b = replayed.models[0].bvc;
        ASSERT_EQ(a.size(), b.size()) << name;
        ASSERT_EQ(replayed.x.size(), steps.size());
        const double peak = max_abs(a);
        double worst = 0;
        for (std::size_t i = 0; i < a.size(); ++i) worst = std::max(worst, static_cast<double>(std::abs(a[i] - b[i])));
        EXPECT_LE(worst, 1e-6 * peak) << name;
        EXPECT_GT(peak, 0.4) << name;
        // Positions are the sensor's, heading its yaw.
        for (std::size_t i = 0; i < steps.size(); ++i) {
            EXPECT_NEAR(replayed.x[i], steps[i].pose.x, 1e-12);
            EXPECT_NEAR(replayed.z[i], model.sensor.height, 1e-12);
            EXPECT_NEAR(std::abs(wrap_pi(replayed.heading[i] - steps[i].pose.heading)), 0.0, 1e-12);
        }
    }
}

TEST(Replay, TiltedSensorsAreGravityAligned) {
    // A hand-held sensor rolls and pitches: exported and replayed, its returns are the simulator's
    // own world-frame returns; and every return from the flat ceiling (z = 2.5) lies at the
    // ceiling's height above the sensor, whatever the tilt.
    const World world = World::cross({.tilt_deg = 0});
    const LidarSpec sensor = LidarSpec::spherical(false);
    std::vector<ModelStep> steps;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> angle(-0.6, 0.6);
    for (int i = 0; i < 6; ++i)
        steps.push_back({static_cast<double>(i), Pose{-4.2 + 0.1 * i, -4.3, 0.4, angle(rng), angle(rng), angle(rng)},
                         false, std::nullopt});
    TempDir dir;
    const auto rec = export_walk(world, steps, sensor, dir / "tilted", recording::ScanWriteFormat::pcd_f8);
    RecordedReturnParams p;
    p.min_range = 0;
    const Lidar lidar(sensor);
    int ceiling_hits = 0;
    for (std::size_t i = 0; i < steps.size(); ++i) {
        Scan replayed;
        returns_from_points(rec->load(i).xyz, rec->poses[i].world_from_sensor.linear(), p, ReturnSelection::all,
                            replayed);
        const Scan simulated = lidar.scan(world, steps[i].pose);
        ASSERT_EQ(replayed.size(), simulated.size());
        const double sensor_z = rec->poses[i].world_from_sensor.translation().z();
        for (std::size_t k = 0; k < replayed.size(); ++k) {
            ASSERT_NEAR(replayed[k].range, simulated[k].range, 1e-12);
            ASSERT_NEAR(replayed[k].azimuth, simulated[k].azimuth, 1e-12);
            ASSERT_NEAR(replayed[k].elevation, simulated[k].elevation, 1e-12);
            const double height = replayed[k].range * std::sin(replayed[k].elevation);
            const Vec3 hit = rec->poses[i].world_from_sensor.translation() +
                             replayed[k].range * Vec3(std::cos(replayed[k].elevation) * std::cos(replayed[k].azimuth),
                                                      std::cos(replayed[k].elevation) * std::sin(replayed[k].azimuth),
                                                      std::sin(replayed[k].elevation));
            // Inside the arena away from the walls, a hit at the ceiling's height is on the ceiling.
            if (std::abs(hit.z() - 2.5) < 1e-6 && std::abs(hit.x()) < 4.99 && std::abs(hit.y()) < 4.99) {
                ++ceiling_hits;
                ASSERT_NEAR(height, 2.5 - sensor_z, 1e-9);
            }
        }
    }
    EXPECT_GT(ceiling_hits, 1000);
    // The recording's heading is the yaw of the forward axis.
    const GroupResult r = run_replay({replay_trial(recorded_source(rec, p), model_preset("3d-0.2"), false)});
    for (std::size_t i = 0; i < steps.size(); ++i) EXPECT_NEAR(r.heading[i], steps[i].pose.heading, 1e-12);
}

TEST(Replay, IsDeterministicAndUsesGivenWeights) {
    const World world = World::cross({.tilt_deg = 30});
    std::vector<ModelStep> steps = random_walk(world, 0.01, 5);
    steps.resize(20);
    TempDir dir;
    const ModelSpec model = model_preset("3d-0.1");
    const auto rec = export_walk(world, steps, model.sensor, dir / "rec", recording::ScanWriteFormat::kitti_bin);
    const ReplaySource source = recorded_source(rec, {});
    const GroupResult a = run_replay({replay_trial(source, model, true)});
    const GroupResult b = run_replay({replay_trial(source, model, true)});
    EXPECT_EQ(a.models[0].bvc, b.models[0].bvc);
    EXPECT_EQ(a.models[0].rates, b.models[0].rates);
    EXPECT_EQ(a.models[0].weights, b.models[0].weights);

    // Frozen weights from the learned run: kept exactly; learning from them changes them.
    auto w = std::make_shared<InitialWeights>();
    w->source = "a";
    w->values = a.models[0].weights;
    w->n_place = a.models[0].n_place;
    w->n_bvc = a.models[0].n_bvc;
    const GroupResult frozen = run_replay({replay_trial(source, model, false, w)});
    EXPECT_EQ(frozen.models[0].weights, w->values);
    const GroupResult relearned = run_replay({replay_trial(source, model, true, w)});
    EXPECT_NE(relearned.models[0].weights, w->values);
    // Weights of another shape are refused, naming both shapes.
    auto wrong = std::make_shared<InitialWeights>(*w);
    wrong->n_bvc = 10;
    wrong->values.resize(static_cast<std::size_t>(wrong->n_place) * 10);
    EXPECT_THROW(replay_trial(source, model, false, wrong), InputError);
}

TEST(Replay, TrialsWithoutAWorld) {
    // A random walk needs a world; a model's own sensor cannot be cast without one.
    TrialConfig t;
    t.world = WorldSpec::none();
    EXPECT_THROW(t.validate(), InputError);
    EXPECT_THROW(RandomWalkSpec().make(nullptr, 0), InputError);
    std::vector<ModelStep> steps{{0.0, Pose{}, false, std::nullopt}, {1.0, Pose{}, false, std::nullopt}};
    t.agent = std::make_shared<TrajectorySpec>(steps, "two");
    t.protocol.explore_hours = 0;
    t.protocol.sample_hours = 1;
    EXPECT_THROW(run_trial_group(nullptr, {t}), InputError);
    // The trial's text names the returns; a trial with returns keeps older trials' text unchanged.
    TrialConfig plain;
    EXPECT_EQ(plain.canonical().find("returns:"), std::string::npos);
    EXPECT_EQ(plain.canonical().find("weights:"), std::string::npos);
}

TEST(RecordingFiles, ErrorsNameTheScanAndFoldersAreAllOrNothing) {
    TempDir dir;
    recording::PointCloud cloud;
    cloud.xyz = {1, 2, 3, 4, 5, 6};
    std::vector<recording::PointCloud> clouds(3, cloud);
    std::vector<recording::PoseRecord> poses(3);
    for (int i = 0; i < 3; ++i) poses[i].time = 10.0 + i;
    recording::write_recording(dir / "rec", clouds, poses, recording::ScanWriteFormat::pcd_f4);
    EXPECT_TRUE(fs::exists(dir / "rec" / "000002.pcd"));
    // Rewriting an earlier recording replaces it whole.
    recording::write_recording(dir / "rec", {cloud, cloud}, {poses[0], poses[1]}, recording::ScanWriteFormat::ply);
    EXPECT_FALSE(fs::exists(dir / "rec" / "000002.pcd"));
    EXPECT_TRUE(fs::exists(dir / "rec" / "000001.ply"));
    // A folder holding anything else is not overwritten.
    std::ofstream(dir / "rec" / "notes.txt") << "mine";
    EXPECT_THROW(recording::write_recording(dir / "rec", clouds, poses, recording::ScanWriteFormat::ply), InputError);
    EXPECT_TRUE(fs::exists(dir / "rec" / "notes.txt"));
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1);  // no temporaries

    // A broken scan: the error names the recording, the scan's index and its file.
    recording::write_recording(dir / "rec2", clouds, poses, recording::ScanWriteFormat::pcd_f4);
    std::ofstream(dir / "rec2" / "000001.pcd", std::ios::trunc) << "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\n";
    const auto rec = recording::open_recording(dir / "rec2" / "scans.txt", dir / "rec2" / "poses.txt");
    try {
        rec.load(1);
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find("scan 1"), std::string::npos) << m;
        EXPECT_NE(m.find("000001.pcd"), std::string::npos) << m;
    }
    // Times that do not increase: the error names the scan.
    poses[2].time = 10.5;
    recording::write_recording(dir / "rec3", clouds, poses, recording::ScanWriteFormat::pcd_f4);
    const auto rec3 = std::make_shared<const recording::Recording>(
        recording::open_recording(dir / "rec3" / "scans.txt", dir / "rec3" / "poses.txt"));
    try {
        recorded_source(rec3, {});
        ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("scan 2"), std::string::npos) << e.what();
    }
}

TEST(VoxelMap, MeansPerVoxelInTheWorldFrame) {
    recording::VoxelMapParams p;
    p.voxel = 0.1;
    p.min_range = 0.5;
    recording::VoxelMap map(p);
    recording::PointCloud scan;
    // In the sensor frame; the pose moves them by (10, 0, 0) and turns them 90° about z.
    scan.xyz = {1.01, 0.02, 0.03,  // -> (9.98, 1.01, 0.03): voxel (99, 10, 0)
                1.03, 0.04, 0.05,  // -> (9.96, 1.03, 0.05): same voxel
                2.00, 0.05, 0.05,  // -> (9.95, 2.00, 0.05): voxel (99, 20, 0)
                0.1,  0.1,  0.1};  // nearer than min_range: left out
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::AngleAxisd(pi / 2, Vec3::UnitZ()).toRotationMatrix();
    pose.translation() = Vec3(10, 0, 0);
    map.add(scan, pose);
    EXPECT_EQ(map.points_added(), 3u);
    const auto cloud = map.cloud();
    ASSERT_EQ(cloud.size(), 2u);
    EXPECT_NEAR(cloud.xyz[0], 9.97, 1e-12);
    EXPECT_NEAR(cloud.xyz[1], 1.02, 1e-12);
    EXPECT_NEAR(cloud.xyz[2], 0.04, 1e-12);
    EXPECT_NEAR(cloud.xyz[4], 2.00, 1e-12);
    p.min_points = 2;
    recording::VoxelMap dense(p);
    dense.add(scan, pose);
    EXPECT_EQ(dense.cloud().size(), 1u);
    p.voxel = 0;
    EXPECT_THROW(recording::VoxelMap{p}, InputError);
}

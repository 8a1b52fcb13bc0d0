// Recordings: reading a binary PCD scan (bytes per second); one real scan's preprocessing and its
// 3d-3l BVC layer, beside the dense reference sum (every return x every cell) in the same run; and
// the whole recording replayed. On hall-lidar when the data is there (its scan 0030: 79 254 points),
// else on synthetic scans of the same size (the label says which).
#include <benchmark/benchmark.h>

#include <unistd.h>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <random>

#include "../support/bvc_reference.hpp"
#include "bvc3d/config/model_yaml.hpp"
#include "bvc3d/experiment/replay.hpp"
#include "bvc3d/recording/pcd.hpp"
#include "bvc3d/recording/recording.hpp"
#include "bvc3d/sensor/recorded_returns.hpp"

using namespace bvc3d;
using namespace bvc3d::recording;
namespace fs = std::filesystem;

namespace {

// A synthetic scan written to a temporary file, removed at the end of the benchmark.
class SyntheticScan {
public:
    SyntheticScan() : path_(fs::temp_directory_path() / ("bvc3d-bench-" + std::to_string(::getpid()) + ".pcd")) {
        std::mt19937 rng(1);
        std::uniform_real_distribution<double> coordinate(-30, 30);
        PointCloud cloud;
        for (int i = 0; i < 3 * 80000; ++i) cloud.xyz.push_back(coordinate(rng));
        write_pcd(path_, cloud, PcdEncoding::binary, PcdPrecision::f4);
    }
    ~SyntheticScan() { fs::remove(path_); }
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

void BM_ReadPcdBinary(benchmark::State& state) {
    const fs::path hall_scan = BVC3D_SOURCE_DIR "/../shared/data/hall-lidar/0030.pcd";
    std::optional<SyntheticScan> synthetic;
    if (!fs::exists(hall_scan)) synthetic.emplace();
    const fs::path file = synthetic ? synthetic->path() : hall_scan;
    state.SetLabel(synthetic ? "synthetic 80000 points" : "hall-lidar 0030.pcd");
    std::size_t points = 0;
    for (auto _ : state) {
        const PointCloud cloud = read_pcd(file);
        points = cloud.size();
        benchmark::DoNotOptimize(cloud.xyz.data());
    }
    state.counters["points"] = static_cast<double>(points);
    state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * fs::file_size(file)));
}

const fs::path hall_dir = BVC3D_SOURCE_DIR "/../shared/data/hall-lidar";

// A hand-held scan of a 30 x 20 x 8 m hall without the data: 80 000 random directions, each point
// on the box around the sensor with 2 cm of range noise, seen through a tilted pose.
PointCloud synthetic_scan(unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> n(0, 1);
    const Eigen::Vector3d lo(-12, -8, -1.7), hi(18, 12, 6.3);
    PointCloud cloud;
    for (int i = 0; i < 80000; ++i) {
        Eigen::Vector3d d(n(rng), n(rng), n(rng));
        d.normalize();
        double t = INFINITY;
        for (int k = 0; k < 3; ++k) t = std::min(t, (d[k] > 0 ? hi[k] : lo[k]) / d[k]);
        const Eigen::Vector3d p = (t + 0.02 * n(rng)) * d;
        cloud.xyz.insert(cloud.xyz.end(), {p.x(), p.y(), p.z()});
    }
    return cloud;
}

Eigen::Matrix3d synthetic_tilt() {
    return (Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()))
        .toRotationMatrix();
}

// One real scan (hall-lidar 0030) with its rotation, or a synthetic one.
struct OneScan {
    PointCloud cloud;
    Eigen::Matrix3d rotation;
    std::string label;
};
OneScan one_scan() {
    if (fs::exists(hall_dir / "poses.csv")) {
        const Recording rec = open_recording(hall_dir, hall_dir / "poses.csv");
        return {rec.load(30), rec.poses[30].world_from_sensor.linear(), "hall-lidar 0030"};
    }
    return {synthetic_scan(1), synthetic_tilt(), "synthetic 80000 points"};
}

void BM_PreprocessRealScan(benchmark::State& state, std::string preset) {
    const OneScan scan = one_scan();
    const ModelSpec model = config::resolve_model(preset);
    const ReturnSelection s = selection_for(model.sensor, model.bvc.elevations.empty());
    Scan out;
    for (auto _ : state) {
        returns_from_points(scan.cloud.xyz, scan.rotation, {}, s, out);
        benchmark::DoNotOptimize(out.data());
    }
    state.SetLabel(scan.label);
    state.counters["points"] = static_cast<double>(scan.cloud.size());
    state.counters["returns"] = static_cast<double>(out.size());
}

// The layer alone, on the returns the model keeps.
void BM_BvcRealScan(benchmark::State& state, std::string preset) {
    const OneScan scan = one_scan();
    const ModelSpec model = config::resolve_model(preset);
    Scan returns;
    returns_from_points(scan.cloud.xyz, scan.rotation, {}, selection_for(model.sensor, model.bvc.elevations.empty()),
                        returns);
    const BoundaryVectorLayer layer(model.bvc);
    std::vector<double> rates(layer.n_cells());
    for (auto _ : state) {
        layer.rates(returns, rates);
        benchmark::DoNotOptimize(rates.data());
    }
    state.SetLabel(scan.label);
    state.counters["returns"] = static_cast<double>(returns.size());
}

// The same returns through the dense reference: every return x every cell.
void BM_BvcRealScanDense(benchmark::State& state, std::string preset) {
    const OneScan scan = one_scan();
    const ModelSpec model = config::resolve_model(preset);
    Scan returns;
    returns_from_points(scan.cloud.xyz, scan.rotation, {}, selection_for(model.sensor, model.bvc.elevations.empty()),
                        returns);
    for (auto _ : state) {
        const auto rates = reference::bvc_rates(model.bvc, returns);
        benchmark::DoNotOptimize(rates.data());
    }
    state.SetLabel(scan.label);
    state.counters["returns"] = static_cast<double>(returns.size());
}

// A synthetic 60-scan recording in a temporary folder, removed at the end of the benchmark.
class SyntheticRecording {
public:
    SyntheticRecording() : dir_(fs::temp_directory_path() / ("bvc3d-bench-rec-" + std::to_string(::getpid()))) {
        std::vector<PointCloud> clouds;
        std::vector<PoseRecord> poses(60);
        for (int i = 0; i < 60; ++i) {
            clouds.push_back(synthetic_scan(static_cast<unsigned>(i)));
            poses[i].world_from_sensor.linear() = synthetic_tilt();
            poses[i].world_from_sensor.translation() = Eigen::Vector3d(0.9 * i, 0, 0);
            poses[i].time = i;
        }
        write_recording(dir_, clouds, poses, ScanWriteFormat::pcd_f4);
    }
    ~SyntheticRecording() { fs::remove_all(dir_); }
    const fs::path& dir() const { return dir_; }

private:
    fs::path dir_;
};

// The whole recording replayed through one model: reading, preprocessing, BVC layer and place
// cells (frozen), as `bvc3d replay` runs it (without writing the trial file).
void BM_ReplayRecording(benchmark::State& state, std::string preset) {
    std::optional<SyntheticRecording> synthetic;
    std::shared_ptr<const Recording> rec;
    if (fs::exists(hall_dir / "poses.csv")) {
        rec = std::make_shared<const Recording>(open_recording(hall_dir, hall_dir / "poses.csv"));
    } else {
        synthetic.emplace();
        rec = std::make_shared<const Recording>(open_recording(synthetic->dir(), synthetic->dir() / "poses.txt"));
    }
    const TrialConfig trial = replay_trial(recorded_source(rec, {}), config::resolve_model(preset), false);
    for (auto _ : state) {
        const GroupResult r = run_replay({trial});
        benchmark::DoNotOptimize(r.models[0].rates.data());
    }
    state.SetLabel(synthetic ? "synthetic, 60 scans" : "hall-lidar, 60 scans");
    state.counters["scans"] = static_cast<double>(rec->size());
}

}  // namespace

BENCHMARK(BM_ReadPcdBinary)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PreprocessRealScan, 3d_3l, std::string("3d-3l"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_PreprocessRealScan, 2d, std::string("2d"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BvcRealScan, 3d_3l, std::string("3d-3l"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_BvcRealScanDense, 3d_3l, std::string("3d-3l"))->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK_CAPTURE(BM_BvcRealScan, 2d, std::string("2d"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReplayRecording, 3d_3l, std::string("3d-3l"))->Unit(benchmark::kMillisecond);

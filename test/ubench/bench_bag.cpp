// Bags: reading a bag's clouds as a recording's scans (Recording::load: the message read, decompressed
// and decoded, its x, y, z gathered as doubles) beside reading the same scans as binary PCD files, in
// bytes of cloud data per second. Ten synthetic os1-128 scans (131 072 points, x y z float32 in a
// point step of 16 bytes, as drivers pad them), in a ROS 1 bag (lz4 chunks, as bvc3d writes them), an
// MCAP file (uncompressed, and zstd chunks) and ten PCD files (x y z float32).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <memory>
#include <random>

#include "bvc3d/recording/bag.hpp"
#include "bvc3d/recording/bag_recording.hpp"
#include "bvc3d/recording/cdr.hpp"
#include "bvc3d/recording/mcap.hpp"
#include "bvc3d/recording/pcd.hpp"

using namespace bvc3d::recording;
namespace fs = std::filesystem;

namespace {

constexpr int scans = 10;
constexpr std::uint32_t points = 128 * 1024;  // an os1-128 turn: 128 rows x 1024 columns

struct BagFiles {
    fs::path dir;
    std::vector<CloudMessage> clouds;
    std::vector<StampedTransform> poses;
    BagFiles() : dir(fs::temp_directory_path() / ("bvc3d-bench-bag-" + std::to_string(::getpid()))) {
        fs::create_directories(dir);
        std::mt19937 rng(1);
        std::uniform_real_distribution<float> coordinate(-30, 30);
        for (int s = 0; s < scans; ++s) {
            CloudMessage c;
            c.stamp = 1.0 + 0.1 * s;
            c.frame_id = "lidar";
            c.height = 128;
            c.width = 1024;
            c.fields = {{"x", 0, 7, 1}, {"y", 4, 7, 1}, {"z", 8, 7, 1}, {"intensity", 12, 7, 1}};
            c.point_step = 16;
            c.row_step = 16 * 1024;
            c.data.resize(std::size_t{points} * 16);
            PointCloud pcd;
            for (std::uint32_t i = 0; i < points; ++i) {
                const float v[4] = {coordinate(rng), coordinate(rng), coordinate(rng), 1.0f};
                std::memcpy(c.data.data() + 16 * i, v, 16);
                pcd.xyz.insert(pcd.xyz.end(), {v[0], v[1], v[2]});
            }
            write_pcd(dir / ("scan" + std::to_string(s) + ".pcd"), pcd, PcdEncoding::binary, PcdPrecision::f4);
            StampedTransform t;
            t.stamp = c.stamp;
            t.parent = "map";
            t.child = "lidar";
            clouds.push_back(std::move(c));
            poses.push_back(t);
        }
        ros1::write_bag(dir / "scans.bag", clouds, poses, "/points", "/odom");
        for (const auto& [name, how] :
             {std::pair{"plain.mcap", McapCompression::none}, std::pair{"zstd.mcap", McapCompression::zstd}}) {
            McapWriter w(dir / name, how);
            const auto points_channel =
                w.add_channel("/points", "sensor_msgs/msg/PointCloud2", ros2_definition("sensor_msgs/msg/PointCloud2"));
            const auto odom = w.add_channel("/odom", "nav_msgs/msg/Odometry", ros2_definition("nav_msgs/msg/Odometry"));
            for (int s = 0; s < scans; ++s) {
                const auto ns = static_cast<std::uint64_t>((1.0 + 0.1 * s) * 1e9);
                w.write(odom, ns, cdr::encode_odometry(poses[static_cast<std::size_t>(s)]));
                w.write(points_channel, ns, cdr::encode_cloud(clouds[static_cast<std::size_t>(s)]));
            }
            w.commit();
        }
    }
    ~BagFiles() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
};

const BagFiles& files() {
    static const BagFiles f;
    return f;
}

void BM_ReadBagClouds(benchmark::State& state, std::string file) {
    BagSource source;
    source.bag = files().dir / file;
    source.cloud_topic = "/points";
    source.pose_topic = "/odom";
    const Recording rec = open_bag_recording(source);
    for (auto _ : state)
        for (std::size_t i = 0; i < rec.size(); ++i) {
            const PointCloud cloud = rec.load(i);
            benchmark::DoNotOptimize(cloud.xyz.data());
        }
    state.SetBytesProcessed(state.iterations() * scans * std::int64_t{points} * 16);
    state.counters["scans/s"] =
        benchmark::Counter(static_cast<double>(state.iterations() * scans), benchmark::Counter::kIsRate);
}

// The same scans as binary PCD files (12 bytes a point on disk; counted at the bag's 16 so that the
// two rates compare the same scans).
void BM_ReadSameScansAsPcd(benchmark::State& state) {
    for (auto _ : state)
        for (int s = 0; s < scans; ++s) {
            const PointCloud cloud = read_pcd(files().dir / ("scan" + std::to_string(s) + ".pcd"));
            benchmark::DoNotOptimize(cloud.xyz.data());
        }
    state.SetBytesProcessed(state.iterations() * scans * std::int64_t{points} * 16);
    state.counters["scans/s"] =
        benchmark::Counter(static_cast<double>(state.iterations() * scans), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK_CAPTURE(BM_ReadBagClouds, ros1_lz4, std::string("scans.bag"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadBagClouds, mcap_plain, std::string("plain.mcap"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ReadBagClouds, mcap_zstd, std::string("zstd.mcap"))->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReadSameScansAsPcd)->Unit(benchmark::kMillisecond);

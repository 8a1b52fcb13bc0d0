// The bvc3d_ros node's work per scan (app/ros/node_model.hpp), without ROS: an os1-128 turn (131 072
// points, x y z float32 in a 16-byte point step) as a PointCloud2 would bring it, its points gathered
// (cloud_points) and run through the model (preprocessing, BVC layer, one place-cell step, the revisit
// search over the scans before it). One core; the node must stay under 100 ms to keep up at 10 Hz.
#include <benchmark/benchmark.h>

#include <cstring>
#include <random>

#include "bvc3d/recording/ros_messages.hpp"
#include "node_model.hpp"

using namespace bvc3d;

namespace {

// An os1-128 in a 30 x 20 x 8 m hall: 128 rows from -22.5 to +22.5 degrees, 1024 columns, 2 cm noise.
recording::CloudMessage os1_128_scan(unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0, 0.02);
    const Eigen::Vector3d lo(-12, -8, -1.7), hi(18, 12, 6.3);
    recording::CloudMessage c;
    c.height = 128;
    c.width = 1024;
    c.fields = {{"x", 0, 7, 1}, {"y", 4, 7, 1}, {"z", 8, 7, 1}, {"intensity", 12, 7, 1}};
    c.point_step = 16;
    c.row_step = 16 * 1024;
    c.data.resize(std::size_t{128} * 1024 * 16);
    for (int r = 0; r < 128; ++r)
        for (int k = 0; k < 1024; ++k) {
            const double el = (-22.5 + 45.0 * r / 127) * M_PI / 180, az = 2 * M_PI * k / 1024;
            const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
            double t = INFINITY;
            for (int i = 0; i < 3; ++i) t = std::min(t, (d[i] > 0 ? hi[i] : lo[i]) / d[i]);
            const Eigen::Vector3d p = (t + noise(rng)) * d;
            const float v[4] = {float(p.x()), float(p.y()), float(p.z()), 1.0f};
            std::memcpy(c.data.data() + (std::size_t{1024} * r + k) * 16, v, 16);
        }
    return c;
}

void BM_NodeScan(benchmark::State& state, std::string model) {
    ros_node::NodeParams p;
    p.model = model;
    ros_node::NodeModel node(p);
    const recording::CloudMessage scan = os1_128_scan(1);
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    double t = 0;
    std::size_t returns = 0;
    for (auto _ : state) {
        pose.translation().x() = 0.01 * t;  // a robot creeping along: every scan a new pose
        const auto r = node.step(recording::cloud_points(scan).xyz, pose, t);
        returns = r.returns;
        t += 0.1;
        benchmark::DoNotOptimize(r.bvc.data());
    }
    state.counters["returns"] = static_cast<double>(returns);
    state.counters["scans_per_s"] =
        benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK_CAPTURE(BM_NodeScan, 3d_3l, std::string("3d-3l"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_NodeScan, 3d_0_2, std::string("3d-0.2"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_NodeScan, 3d_0_1, std::string("3d-0.1"))->Unit(benchmark::kMillisecond);

namespace {

// The revisit search alone: one scan's descriptor against an hour of earlier ones at 10 Hz (36 000 of
// 960 BVCs), as the node's step does it (unit vectors, one dot product each).
void BM_NodeRevisitSearchHour(benchmark::State& state) {
    std::mt19937 rng(2);
    std::uniform_real_distribution<float> u(0, 1);
    std::vector<std::vector<float>> history(36000, std::vector<float>(960));
    for (auto& h : history)
        for (auto& v : h) v = u(rng);
    std::vector<float> d(960);
    for (auto& v : d) v = u(rng);
    using V = Eigen::Map<const Eigen::VectorXf>;
    for (auto _ : state) {
        float best = -2;
        for (const auto& h : history) best = std::max(best, V(d.data(), 960).dot(V(h.data(), 960)));
        benchmark::DoNotOptimize(best);
    }
}

}  // namespace

BENCHMARK(BM_NodeRevisitSearchHour)->Unit(benchmark::kMillisecond);

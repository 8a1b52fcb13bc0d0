// Recording stage: reading a binary PCD scan (one hall-lidar scan when the data is there, else a
// synthetic 80 000-point scan of the same layout). Reports bytes of file read per second.
#include <benchmark/benchmark.h>

#include <unistd.h>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <random>

#include "bvc3d/recording/pcd.hpp"

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

}  // namespace

BENCHMARK(BM_ReadPcdBinary)->Unit(benchmark::kMillisecond);

// A fixed number of full model steps of one preset, exactly what BM_FullStep does (cast the rows the
// model needs, BVC rates, place cells learning), for instruction counts and stage timings:
//   model_steps PRESET [STEPS]             per-stage CPU time per step, and a digest of every rate
//   valgrind --tool=callgrind --collect-atstart=no model_steps PRESET STEPS
//                                          instructions of the steps only (callgrind_annotate
//                                          --inclusive=yes splits them by stage)
// The digest (FNV-1a over the 32-bit words of the BVC and place-cell rates of every step) tells whether two
// builds compute the same numbers. scripts/bench --instructions REF builds this file against REF too,
// so it only uses what both have.
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#else
#define CALLGRIND_START_INSTRUMENTATION
#define CALLGRIND_STOP_INSTRUMENTATION
#endif

#include <ctime>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bvc3d/bvc/boundary_vector_layer.hpp"
#include "bvc3d/place/place_cell_network.hpp"
#if __has_include("bvc3d/config/model_spec.hpp")
#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/config/model_spec.hpp"
#else  // before the architecture refactor
#include "bvc3d/experiment/model_spec.hpp"
#include "bvc3d/robot/random_walk.hpp"
#endif

using namespace bvc3d;

namespace {

template <class Step>
Pose pose_of(const Step& s) {
    if constexpr (requires { s.pose; }) return s.pose;
    else return Pose{s.x, s.y, s.heading};
}

struct Digest {
    std::uint64_t h = 1469598103934665603ull;
    void add(const void* p, std::size_t n) {  // n a multiple of 4: 32-bit words
        for (std::size_t i = 0; i < n; i += 4) {
            std::uint32_t w;
            std::memcpy(&w, static_cast<const char*>(p) + i, 4);
            h = (h ^ w) * 1099511628211ull;
        }
    }
};

// The thread's CPU time: on a shared machine, time spent descheduled is not counted.
struct Clock {
    static double now() {
        timespec t;
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
        return static_cast<double>(t.tv_sec) * 1e6 + static_cast<double>(t.tv_nsec) * 1e-3;
    }
};
double us(double d) { return d; }

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: model_steps PRESET [STEPS]\n");
        return 2;
    }
    const std::string preset = argv[1];
    const long steps = argc > 2 ? std::atol(argv[2]) : 2000;
    const ModelSpec model = model_preset(preset);
    const World world = World::cross({.tilt_deg = 45});
    const Lidar lidar(model.sensor);
    const BoundaryVectorLayer layer(model.bvc);
    const auto plan = layer.plan(model.sensor);
    PlaceCellNetwork net(model.bvc.n_cells(), model.place, 1);
    const auto walk = random_walk(world, 0.1, 1);
    std::vector<double> rates(layer.n_cells());
    Scan scan;
    Digest digest;
    double t_scan = 0, t_bvc = 0, t_place = 0;
    std::size_t returns = 0;
    auto one_step = [&](long i, bool timed) {
        const auto t0 = Clock::now();
        lidar.scan(world, pose_of(walk[static_cast<std::size_t>(i) % walk.size()]), scan, {}, plan.rows);
        const auto t1 = Clock::now();
        if (!layer.rates_pruned(scan, plan, rates)) layer.rates(scan, rates);
        const auto t2 = Clock::now();
        const auto v = net.step(rates, true);
        const auto t3 = Clock::now();
        if (!timed) return;
        t_scan += us(t1 - t0);
        t_bvc += us(t2 - t1);
        t_place += us(t3 - t2);
        returns += scan.size();
        digest.add(rates.data(), rates.size() * sizeof(double));
        digest.add(v.data(), v.size() * sizeof(float));
    };
    for (long i = 0; i < 16; ++i) one_step(i, false);  // warm caches and memos
    CALLGRIND_START_INSTRUMENTATION;
    for (long i = 16; i < 16 + steps; ++i) one_step(i, true);
    CALLGRIND_STOP_INSTRUMENTATION;
    const double n = static_cast<double>(steps);
    std::printf("%s: %ld steps, %.0f returns/step; per step: scan %.2f us, BVC %.2f us, place cells %.2f us, "
                "total %.2f us; digest %016llx\n",
                preset.c_str(), steps, static_cast<double>(returns) / n, t_scan / n, t_bvc / n, t_place / n,
                (t_scan + t_bvc + t_place) / n, static_cast<unsigned long long>(digest.h));
}

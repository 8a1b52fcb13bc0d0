// A fixed number of full model steps of one preset, as a trial runs them (cast the rows the model
// needs, BVC rates, place cells learning; the place cells in blocks of BLOCK steps, as the trial runner
// steps them, where the tree has PlaceCellNetwork::step_block), for instruction counts and stage timings:
//   model_steps PRESET [STEPS [BLOCK [DUMP]]]
//                                          per-stage CPU time per step, and a digest of every rate
//                                          (BLOCK: default 16; 1 steps the place cells one call per step;
//                                          DUMP: a file for every step's BVC rates, float64, then every
//                                          step's place-cell rates, float32, to compare two builds' numbers)
//   valgrind --tool=callgrind --instr-atstart=no model_steps PRESET STEPS
//                                          instructions of the steps only (callgrind_annotate
//                                          --inclusive=yes splits them by stage)
// The digest (FNV-1a over the 32-bit words of every step's BVC rates, then of every step's place-cell
// rates) tells whether two builds compute the same numbers, whatever their blocking. scripts/bench
// builds this file against REF too, so it only uses what both have.
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#else
#define CALLGRIND_START_INSTRUMENTATION
#define CALLGRIND_STOP_INSTRUMENTATION
#endif

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <span>
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

template <class Net>
concept HasStepBlock = requires(Net& n, std::span<const double> r, std::span<const char> l) {
    n.step_block(r, l);
};

// `steps` place-cell steps of `net` on rates (steps × n_bvc), learning: in one block where the tree has
// step_block, else one call per step. Returns every step's rates.
template <class Net>
std::vector<float> place_steps(Net& net, const std::vector<double>& rates, std::size_t steps, long block) {
    std::vector<float> out;
    if constexpr (HasStepBlock<Net>) {
        if (block > 1) {
            const std::vector<char> learn(steps, 1);
            const auto v = net.step_block(rates, learn);
            return {v.begin(), v.end()};
        }
    }
    const std::size_t n = rates.size() / steps;
    for (std::size_t k = 0; k < steps; ++k) {
        const auto v = net.step(std::span<const double>(rates.data() + k * n, n), true);
        out.insert(out.end(), v.begin(), v.end());
    }
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: model_steps PRESET [STEPS [BLOCK [DUMP]]]\n");
        return 2;
    }
    const std::string preset = argv[1];
    const long steps = argc > 2 ? std::atol(argv[2]) : 2000;
    const long block = argc > 3 ? std::max(1L, std::atol(argv[3])) : 16;
    std::vector<double> all_bvc;  // for DUMP
    std::vector<float> all_place;
    const ModelSpec model = model_preset(preset);
    const World world = World::cross({.tilt_deg = 45});
    const Lidar lidar(model.sensor);
    const BoundaryVectorLayer layer(model.bvc);
    const auto plan = layer.plan(model.sensor);
    PlaceCellNetwork net(model.bvc.n_cells(), model.place, 1);
    const auto walk = random_walk(world, 0.1, 1);
    const std::size_t n_bvc = layer.n_cells();
    std::vector<double> rates;
    Scan scan;
    Digest bvc_digest, place_digest;
    double t_scan = 0, t_bvc = 0, t_place = 0;
    std::size_t returns = 0;
    // Steps first..first+count-1 (count <= block): scans and BVC rates step by step, then the place cells.
    auto some_steps = [&](long first, long count, bool timed) {
        rates.assign(static_cast<std::size_t>(count) * n_bvc, 0.0);
        for (long k = 0; k < count; ++k) {
            const std::span<double> out(rates.data() + static_cast<std::size_t>(k) * n_bvc, n_bvc);
            const auto t0 = Clock::now();
            lidar.scan(world, pose_of(walk[static_cast<std::size_t>(first + k) % walk.size()]), scan, {}, plan.rows);
            const auto t1 = Clock::now();
            if (!layer.rates_pruned(scan, plan, out)) layer.rates(scan, out);
            const auto t2 = Clock::now();
            if (!timed) continue;
            t_scan += us(t1 - t0);
            t_bvc += us(t2 - t1);
            returns += scan.size();
            bvc_digest.add(out.data(), out.size() * sizeof(double));
            if (argc > 4) all_bvc.insert(all_bvc.end(), out.begin(), out.end());
        }
        const auto t2 = Clock::now();
        const auto v = place_steps(net, rates, static_cast<std::size_t>(count), block);
        const auto t3 = Clock::now();
        if (!timed) return;
        t_place += us(t3 - t2);
        place_digest.add(v.data(), v.size() * sizeof(float));
        if (argc > 4) all_place.insert(all_place.end(), v.begin(), v.end());
    };
    some_steps(0, 16, false);  // warm caches and memos
    CALLGRIND_START_INSTRUMENTATION;
    for (long i = 0; i < steps; i += block) some_steps(16 + i, std::min(block, steps - i), true);
    CALLGRIND_STOP_INSTRUMENTATION;
    if (argc > 4) {
        std::FILE* f = std::fopen(argv[4], "wb");
        if (!f || std::fwrite(all_bvc.data(), sizeof(double), all_bvc.size(), f) != all_bvc.size() ||
            std::fwrite(all_place.data(), sizeof(float), all_place.size(), f) != all_place.size() ||
            std::fclose(f) != 0) {
            std::fprintf(stderr, "model_steps: cannot write %s\n", argv[4]);
            return 1;
        }
    }
    const double n = static_cast<double>(steps);
    Digest digest = bvc_digest;
    digest.add(&place_digest.h, sizeof place_digest.h);
    std::printf(
        "%s: %ld steps, %.0f returns/step; per step: scan %.2f us, BVC %.2f us, place cells %.2f us, "
        "total %.2f us; digest %016llx\n",
        preset.c_str(), steps, static_cast<double>(returns) / n, t_scan / n, t_bvc / n, t_place / n,
        (t_scan + t_bvc + t_place) / n, static_cast<unsigned long long>(digest.h));
}

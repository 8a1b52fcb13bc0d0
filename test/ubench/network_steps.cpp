// A fixed number of steps of a model's whole population network (ray cast, BVC layers, grid and HD cells, every
// place-cell scale learning, blocked populations every 16 steps), as BM_MultiscaleModelStep steps it: cross arena,
// upright walls, the random walk of seed 1, after 32 steps that warm caches and memos.
//   network_steps PRESET [STEPS]           CPU time per step (default 1 600 steps)
//   valgrind --tool=callgrind --instr-atstart=no network_steps PRESET STEPS
//                                          instructions of the steps only (valgrind runs the AVX2 kernels)
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#else
#define CALLGRIND_START_INSTRUMENTATION
#define CALLGRIND_STOP_INSTRUMENTATION
#endif

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>

#include "bvc3d/agent/random_walk.hpp"
#include "bvc3d/config/model_spec.hpp"
#include "bvc3d/config/trial_config.hpp"
#include "bvc3d/experiment/model_network.hpp"

using namespace bvc3d;

namespace {
// The thread's CPU time, s: on a shared machine, time spent descheduled is not counted.
double cpu_seconds() {
    timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}
}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: network_steps PRESET [STEPS]\n");
        return 2;
    }
    const std::string preset = argv[1];
    const long steps = argc > 2 ? std::atol(argv[2]) : 1600;
    const World world = World::cross({.tilt_deg = 0});
    TrialConfig trial;
    trial.model = model_preset(preset);
    trial.seed = 1;
    ModelNetwork models(&world, {trial}, {}, false);
    const auto walk = random_walk(world, 0.2, 1);
    const auto step = [&](long i) {
        models.network.step(walk[static_cast<std::size_t>(i) % walk.size()], i, true, false);
    };
    constexpr long warm = 32;
    for (long i = 0; i < warm; ++i) step(i);
    const double t0 = cpu_seconds();
    CALLGRIND_START_INSTRUMENTATION;
    for (long i = warm; i < warm + steps; ++i) step(i);
    CALLGRIND_STOP_INSTRUMENTATION;
    const double t1 = cpu_seconds();
    models.network.flush();
    std::printf("%s: %ld steps, %.1f us of CPU per step, %.0f steps/s\n", preset.c_str(), steps,
                1e6 * (t1 - t0) / static_cast<double>(steps), static_cast<double>(steps) / (t1 - t0));
}

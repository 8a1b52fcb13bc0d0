// The pool every parallel part of bvc3d runs on (core/parallel.hpp): the jobs rule, every task exactly
// once, the first error and nothing after it, cancellation from the caller, deterministic results.
// Oracles: the kernel's own account of this process's CPUs (/proc/self/status), affinity masks set
// here, cgroup files written here, serial loops.
#include <gtest/gtest.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

#include "../support/temp_dir.hpp"
#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"
#include "bvc3d/core/parallel.hpp"

using namespace bvc3d;
namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

// The CPUs the kernel lets this thread use, from /proc/thread-self/status ("Cpus_allowed_list: 0-3,8").
std::size_t cpus_allowed() {
    std::ifstream in("/proc/thread-self/status");
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("Cpus_allowed_list:", 0) != 0) continue;
        std::istringstream list(line.substr(line.find(':') + 1));
        std::size_t n = 0;
        for (std::string range; std::getline(list, range, ',');) {
            const auto dash = range.find('-');
            n += dash == std::string::npos ? 1
                                           : std::stoul(range.substr(dash + 1)) - std::stoul(range.substr(0, dash)) + 1;
        }
        return n;
    }
    return 0;
}

// Waits (at most 10 s) until `count` reaches `n`; true if it did.
bool all_arrive(std::mutex& m, std::condition_variable& cv, int& count, int n) {
    std::unique_lock lock(m);
    ++count;
    cv.notify_all();
    return cv.wait_for(lock, 10s, [&] { return count >= n; });
}

void write(const fs::path& p, const std::string& text) {
    fs::create_directories(p.parent_path());
    std::ofstream(p) << text;
}

}  // namespace

TEST(Parallel, JobsRule) {
    EXPECT_EQ(thread_count(1), 1u);
    EXPECT_EQ(thread_count(7), 7u);
    EXPECT_EQ(thread_count(0), available_cpus());
    EXPECT_THROW(thread_count(-1), InputError);
    EXPECT_THROW(parallel_for(3, -2, [](std::size_t) {}), InputError);
    // All cores means the CPUs this process may use: the kernel's count, lowered by a quota if there is one.
    const std::size_t allowed = cpus_allowed();
    ASSERT_GT(allowed, 0u);
    EXPECT_LE(available_cpus(), allowed);
    std::ifstream self("/proc/self/cgroup");
    const std::string cgroup((std::istreambuf_iterator<char>(self)), {});
    if (!cgroup_cpu_limit("/sys/fs/cgroup", cgroup)) {
        EXPECT_EQ(available_cpus(), allowed);
    }
}

TEST(Parallel, AllCoresFollowsTheAffinityMask) {
    cpu_set_t before;
    ASSERT_EQ(sched_getaffinity(0, sizeof before, &before), 0);
    int first = 0;
    while (!CPU_ISSET(first, &before)) ++first;
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(first, &one);
    ASSERT_EQ(sched_setaffinity(0, sizeof one, &one), 0);  // this thread only, as taskset -c would
    const std::size_t pinned = available_cpus(), jobs = thread_count(0);
    ASSERT_EQ(sched_setaffinity(0, sizeof before, &before), 0);
    EXPECT_EQ(pinned, 1u);
    EXPECT_EQ(jobs, 1u);
    EXPECT_GE(available_cpus(), 1u);
}

TEST(Parallel, CgroupQuota) {
    const test::TempDir dir("cgroup");
    const fs::path root = dir.path();
    write(root / "cpu.max", "max 100000\n");
    write(root / "jobs" / "cpu.max", "max 100000\n");
    write(root / "jobs" / "mine" / "cpu.max", "150000 100000\n");
    EXPECT_EQ(cgroup_cpu_limit(root, "0::/jobs/mine\n"), 1.5);
    EXPECT_EQ(cgroup_cpu_limit(root, "12:cpu:/\n0::/jobs/mine\n"), 1.5);  // a hybrid system's v1 lines are ignored
    write(root / "jobs" / "cpu.max", "100000 100000\n");  // a parent's smaller quota applies to its children
    EXPECT_EQ(cgroup_cpu_limit(root, "0::/jobs/mine\n"), 1.0);
    EXPECT_EQ(cgroup_cpu_limit(root, "0::/jobs\n"), 1.0);
    EXPECT_EQ(cgroup_cpu_limit(root, "0::/\n"), std::nullopt);         // no limit at the root
    EXPECT_EQ(cgroup_cpu_limit(root, "4:cpu:/jobs\n"), std::nullopt);  // cgroup v1 only
    write(root / "jobs" / "cpu.max", "lots 100000\n");                 // unreadable: no limit from it
    EXPECT_EQ(cgroup_cpu_limit(root, "0::/jobs\n"), std::nullopt);
    EXPECT_EQ(cgroup_cpu_limit(root / "nowhere", "0::/jobs/mine\n"), std::nullopt);
}

TEST(Parallel, EveryTaskExactlyOnce) {
    for (const int jobs : {1, 2, 3, 8}) {
        for (const std::size_t n : {std::size_t(0), std::size_t(1), std::size_t(5), std::size_t(2000)}) {
            std::vector<std::atomic<int>> runs(n);
            parallel_for(n, jobs, [&](std::size_t i) { ++runs[i]; });
            for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(runs[i].load(), 1) << "task " << i << ", jobs " << jobs;
        }
    }
}

TEST(Parallel, JobsThreadsRunAtOnceEvenBeyondTheCores) {
    // Each of 6 tasks waits until all 6 have started: it ends only if 6 threads run them at once.
    std::mutex m;
    std::condition_variable cv;
    int started = 0;
    std::atomic<int> met{0};
    std::set<std::thread::id> ids;
    parallel_for(6, 6, [&](std::size_t) {
        if (all_arrive(m, cv, started, 6)) ++met;
        const std::lock_guard lock(m);
        ids.insert(std::this_thread::get_id());
    });
    EXPECT_EQ(met.load(), 6);
    EXPECT_EQ(ids.size(), 6u);
    EXPECT_EQ(ids.count(std::this_thread::get_id()), 0u);  // the caller waits; it runs no task
    // One worker (no tick) is the calling thread itself: thread-keyed caches stay warm across calls.
    std::thread::id ran_on;
    run_workers(1, [&](std::size_t) { ran_on = std::this_thread::get_id(); });
    EXPECT_EQ(ran_on, std::this_thread::get_id());
}

TEST(Parallel, ResultsDoNotDependOnTheThreadCount) {
    // Each task writes its own slot; the serial loop is the oracle, to the bit.
    const std::size_t n = 5000;
    auto f = [](std::size_t i) {
        double x = 0;
        for (int k = 1; k < 200; ++k) x += std::sin(static_cast<double>(i) * k) / k;
        return x;
    };
    std::vector<double> serial(n);
    for (std::size_t i = 0; i < n; ++i) serial[i] = f(i);
    for (const int jobs : {1, 2, 3, 7}) {
        std::vector<double> out(n, -1.0);
        parallel_for(n, jobs, [&](std::size_t i) { out[i] = f(i); });
        EXPECT_EQ(out, serial) << "jobs " << jobs;
    }
}

TEST(Parallel, TheFirstErrorIsRethrownAndStopsTheOthers) {
    for (const int jobs : {1, 2, 4}) {
        std::atomic<int> ran{0};
        try {
            parallel_for(100000, jobs, [&](std::size_t i) {
                ++ran;
                if (i == 37) throw InputError("task 37 is bad");
                std::this_thread::sleep_for(1ms);
            });
            ADD_FAILURE() << "no error";
        } catch (const InputError& e) {  // its own type and message
            EXPECT_STREQ(e.what(), "task 37 is bad");
        }
        EXPECT_LT(ran.load(), 1000) << "tasks kept starting after the error, jobs " << jobs;
    }
    // A worker busy in a long task sees the cancellation (poll_cancel), and its Interrupted, or an error it
    // throws after the first, does not replace the first error.
    std::atomic<bool> second_saw_cancel{false};
    try {
        run_workers(3, [&](std::size_t k) {
            if (k == 0) {
                std::this_thread::sleep_for(20ms);
                throw std::runtime_error("first");
            }
            const auto until = std::chrono::steady_clock::now() + 10s;
            while (!cancel_flag()->load() && std::chrono::steady_clock::now() < until) std::this_thread::sleep_for(1ms);
            second_saw_cancel = cancel_flag()->load();
            if (k == 1) throw std::runtime_error("second");
            poll_cancel();  // k == 2: Interrupted
            ADD_FAILURE() << "poll_cancel did not throw";
        });
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "first");
    }
    EXPECT_TRUE(second_saw_cancel.load());
}

TEST(Parallel, CancelledByTheCaller) {
    for (const int jobs : {1, 3}) {
        // Already set: no task starts.
        std::atomic<bool> stop{true};
        std::atomic<int> ran{0};
        {
            const CancelScope scope(&stop);
            EXPECT_THROW(parallel_for(50, jobs, [&](std::size_t) { ++ran; }), Interrupted);
        }
        EXPECT_EQ(ran.load(), 0) << "jobs " << jobs;
        // Set while the tasks run (by the caller's tick, as Python's Ctrl-C check does): the workers stop.
        stop = false;
        ParallelOptions options;
        options.tick_every = 5ms;
        int ticks = 0;
        const auto caller = std::this_thread::get_id();
        bool ticked_on_caller = true;
        options.tick = [&] {
            ticked_on_caller = ticked_on_caller && std::this_thread::get_id() == caller;
            if (++ticks == 3) stop = true;
        };
        {
            const CancelScope scope(&stop);
            EXPECT_THROW(parallel_for(
                             1000000, jobs, [&](std::size_t) { std::this_thread::sleep_for(100us); }, options),
                         Interrupted);
        }
        EXPECT_GE(ticks, 3);
        EXPECT_TRUE(ticked_on_caller);
    }
}

TEST(Parallel, ATickThatThrowsStopsTheWorkers) {
    ParallelOptions options;
    options.tick_every = 1ms;
    options.tick = [] { throw std::runtime_error("progress failed"); };
    try {
        run_workers(
            2,
            [](std::size_t) {
                while (true) {
                    poll_cancel();
                    std::this_thread::sleep_for(1ms);
                }
            },
            options);
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "progress failed");
    }
}

TEST(Parallel, NestedPoolsHearTheOuterCancellation) {
    // Worker 1 runs a pool of its own, whose tasks wait for a cancellation; worker 0's error must reach them.
    std::atomic<bool> inner_cancelled{false};
    try {
        run_workers(2, [&](std::size_t k) {
            if (k == 0) {
                std::this_thread::sleep_for(30ms);
                throw std::runtime_error("outer");
            }
            try {
                parallel_for(2, 2, [&](std::size_t) {
                    const auto until = std::chrono::steady_clock::now() + 10s;
                    while (std::chrono::steady_clock::now() < until) {
                        poll_cancel();
                        std::this_thread::sleep_for(1ms);
                    }
                });
            } catch (const Interrupted&) {
                inner_cancelled = true;
                throw;
            }
        });
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "outer");
    }
    EXPECT_TRUE(inner_cancelled.load());
}

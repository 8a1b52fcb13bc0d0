#include "bvc3d/core/parallel.hpp"

#include <sched.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>
#include <vector>

#include "bvc3d/core/cancel.hpp"
#include "bvc3d/core/error.hpp"

namespace bvc3d {

namespace {

namespace fs = std::filesystem;

// The CPUs of this thread's affinity mask (the process's, unless someone narrowed this thread's); 0 if unknown.
std::size_t affinity_count() {
    for (std::size_t cpus = CPU_SETSIZE; cpus <= (1u << 20); cpus *= 2) {
        cpu_set_t* set = CPU_ALLOC(cpus);
        if (!set) return 0;
        const std::size_t bytes = CPU_ALLOC_SIZE(cpus);
        const int ok = sched_getaffinity(0, bytes, set);
        const auto count = ok == 0 ? static_cast<std::size_t>(CPU_COUNT_S(bytes, set)) : 0;
        CPU_FREE(set);
        if (ok == 0) return count;
        if (errno != EINVAL) return 0;  // EINVAL: the kernel's mask is larger than ours
    }
    return 0;
}

std::string file_text(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace

std::optional<double> cgroup_cpu_limit(const fs::path& root, const std::string& self) {
    std::istringstream lines(self);
    std::string cgroup;
    for (std::string line; std::getline(lines, line);)
        if (line.rfind("0::", 0) == 0) cgroup = line.substr(3);
    if (cgroup.empty()) return std::nullopt;
    std::optional<double> limit;
    // The quota of every cgroup from the process's up to the hierarchy's root applies.
    for (fs::path rel = fs::path(cgroup).relative_path().lexically_normal();; rel = rel.parent_path()) {
        std::istringstream max(file_text(root / rel / "cpu.max"));
        std::string quota;
        double period = 0;
        if (max >> quota >> period && quota != "max" && period > 0) {
            char* end = nullptr;
            const double cpus = std::strtod(quota.c_str(), &end) / period;
            if (*end == '\0' && cpus > 0) limit = std::min(limit.value_or(cpus), cpus);
        }
        if (rel.empty() || rel == ".") break;
    }
    return limit;
}

std::size_t available_cpus() {
    std::size_t n = affinity_count();
    if (n == 0) n = std::thread::hardware_concurrency();
    if (const auto limit = cgroup_cpu_limit("/sys/fs/cgroup", file_text("/proc/self/cgroup")))
        n = std::min(n == 0 ? SIZE_MAX : n, static_cast<std::size_t>(std::ceil(*limit)));
    return std::max<std::size_t>(n, 1);
}

std::size_t thread_count(int jobs) {
    if (jobs < 0) throw InputError("jobs must be >= 0 (0: one per CPU), got " + std::to_string(jobs));
    return jobs > 0 ? static_cast<std::size_t>(jobs) : available_cpus();
}

void run_workers(std::size_t threads, const std::function<void(std::size_t)>& worker, const ParallelOptions& options) {
    if (threads == 0) return;
    if (threads == 1 && !options.tick) return worker(0);  // under the caller's own cancel flag

    const std::atomic<bool>* caller_stop = cancel_flag();
    std::atomic<bool> cancel{caller_stop && caller_stop->load()};
    std::mutex mutex;
    std::condition_variable finished;
    std::size_t running = threads;
    std::exception_ptr error;
    bool interrupted = false;
    const auto fail = [&](std::exception_ptr e) {
        {
            const std::lock_guard lock(mutex);
            if (!error) error = e;
        }
        cancel = true;
    };
    const auto body = [&](std::size_t k) {
        {
            const CancelScope scope(&cancel);
            try {
                worker(k);
            } catch (const Interrupted&) {
                const std::lock_guard lock(mutex);
                interrupted = true;
            } catch (...) {
                fail(std::current_exception());
            }
        }
        const std::lock_guard lock(mutex);
        if (--running == 0) finished.notify_all();
    };

    std::vector<std::jthread> pool;
    pool.reserve(threads);
    try {
        for (std::size_t k = 0; k < threads; ++k) pool.emplace_back(body, k);
    } catch (...) {  // no thread to be had: the started ones stop, and are joined
        cancel = true;
        const std::lock_guard lock(mutex);
        running -= threads - pool.size();
        if (!error) error = std::current_exception();
    }

    // The calling thread: forwards its cancel flag and ticks until every worker has returned.
    auto next_tick = std::chrono::steady_clock::now() + options.tick_every;
    std::unique_lock lock(mutex);
    while (running > 0) {
        if (!caller_stop && !options.tick) {
            finished.wait(lock, [&] { return running == 0; });
            break;
        }
        if (finished.wait_for(lock, stop_poll, [&] { return running == 0; })) break;
        lock.unlock();
        if (caller_stop && caller_stop->load()) cancel = true;
        if (options.tick && std::chrono::steady_clock::now() >= next_tick) {
            next_tick += options.tick_every;
            try {
                options.tick();
            } catch (...) {
                fail(std::current_exception());
            }
            if (caller_stop && caller_stop->load()) cancel = true;
        }
        lock.lock();
    }
    lock.unlock();
    pool.clear();  // joins
    if (error) std::rethrow_exception(error);
    if (interrupted) throw Interrupted();
}

void parallel_for(std::size_t n, int jobs, const std::function<void(std::size_t)>& task,
                  const ParallelOptions& options) {
    std::atomic<std::size_t> next{0};
    run_workers(
        std::min(n, thread_count(jobs)),
        [&](std::size_t) {
            for (std::size_t i; (i = next++) < n;) {
                poll_cancel();  // none starts once the pool is cancelled
                task(i);
            }
        },
        options);
}

}  // namespace bvc3d

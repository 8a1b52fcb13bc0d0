#pragma once
// Work on several threads, written once: how many threads a `jobs` option means, and the pool every
// parallel part of bvc3d runs on (the experiment engine, the elevation chooser, place recognition,
// the cosine search, the program's parallel commands).
// Takes: a thread count (or a `jobs` value) and the work. Gives: the work done — every task exactly
// once — or the first error, the other workers cancelled; or Interrupted when the caller was.
//
// Cancellation: each worker runs under a CancelScope of the pool's own flag, so that inside a worker
// cancel_flag() is that flag (a trial runner's `stop`) and poll_cancel() throws Interrupted once it is
// set. The pool sets it at the first exception of any worker and when the calling thread's own cancel
// flag is set (Ctrl-C: within stop_poll). Results never depend on the number of threads as long as
// each task writes only its own outputs (the callers' rule; nothing here is reduced across threads).
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

namespace bvc3d {

// The CPUs this process may use: the CPUs of its affinity mask (sched_getaffinity: what `nproc`
// counts, narrowed by taskset, cpusets and batch schedulers), lowered to a cgroup v2 CPU quota
// (`cpu.max`, as docker --cpus and Kubernetes limits set it) rounded up. At least 1.
std::size_t available_cpus();

// The CPU limit of a cgroup v2 quota: the smallest quota / period of `cpu.max` in the cgroup named by
// `self` (the text of /proc/self/cgroup, its "0::/path" line) and its ancestors, under the hierarchy
// mounted at `root`; nullopt when none sets one (or there is no cgroup v2).
std::optional<double> cgroup_cpu_limit(const std::filesystem::path& root, const std::string& self);

// The rule of every `--jobs`, `jobs=` and `threads` option: jobs > 0 is that many threads, 0 is
// available_cpus(). A negative value is an InputError.
std::size_t thread_count(int jobs);

// How often the calling thread looks at its cancel flag while the workers run.
inline constexpr std::chrono::milliseconds stop_poll{20};

struct ParallelOptions {
    // Called on the calling thread about every `tick_every` while the workers run (progress). It may set
    // the caller's cancel flag to stop them; an exception it throws stops them as a worker's would.
    std::function<void()> tick;
    std::chrono::milliseconds tick_every{200};
};

// Runs worker(k) for k = 0 … threads − 1, each on a thread of its own, while the calling thread waits
// (forwarding its cancel flag, calling the tick); one worker without a tick runs on the calling thread.
// Rethrows the first exception other than Interrupted once every worker has returned; else Interrupted
// if any worker was interrupted.
void run_workers(std::size_t threads, const std::function<void(std::size_t worker)>& worker,
                 const ParallelOptions& options = {});

// task(i) for every i in [0, n), each exactly once, on min(n, thread_count(jobs)) workers that take the
// next index in turn; no task starts once the pool is cancelled (Interrupted, or the first error, is
// then thrown, so a return means every task ran).
void parallel_for(std::size_t n, int jobs, const std::function<void(std::size_t i)>& task,
                  const ParallelOptions& options = {});

}  // namespace bvc3d

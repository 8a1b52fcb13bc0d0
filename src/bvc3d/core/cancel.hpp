#pragma once
// Cooperative cancellation of long calls. A caller that can be interrupted (a Python binding, on
// Ctrl-C) installs a flag for the thread doing the work; long loops call poll_cancel() now and
// then, which throws Interrupted once the flag is set. Without a flag poll_cancel() does nothing.
#include <atomic>
#include <stdexcept>

namespace bvc3d {

// A run stopped on request (Ctrl-C, SIGTERM); what was checkpointed is kept.
class Interrupted : public std::runtime_error {
public:
    Interrupted() : std::runtime_error("interrupted") {}
};

// Installs `flag` as this thread's cancel flag for the scope's lifetime (scopes nest).
class CancelScope {
public:
    explicit CancelScope(const std::atomic<bool>* flag);
    ~CancelScope();
    CancelScope(const CancelScope&) = delete;
    CancelScope& operator=(const CancelScope&) = delete;

private:
    const std::atomic<bool>* previous_;
};

// This thread's cancel flag, or nullptr.
const std::atomic<bool>* cancel_flag();

// Throws Interrupted if this thread's cancel flag is set. Cheap: call it every few thousand
// iterations of a long loop.
inline void poll_cancel() {
    const auto* flag = cancel_flag();
    if (flag && flag->load(std::memory_order_relaxed)) throw Interrupted();
}

}  // namespace bvc3d

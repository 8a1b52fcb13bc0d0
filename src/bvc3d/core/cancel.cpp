#include "bvc3d/core/cancel.hpp"

namespace bvc3d {

namespace {
// Per thread and scoped by CancelScope: the only state is which flag the current call listens to.
thread_local const std::atomic<bool>* current_flag = nullptr;
}  // namespace

CancelScope::CancelScope(const std::atomic<bool>* flag) : previous_(current_flag) { current_flag = flag; }
CancelScope::~CancelScope() { current_flag = previous_; }

const std::atomic<bool>* cancel_flag() { return current_flag; }

}  // namespace bvc3d

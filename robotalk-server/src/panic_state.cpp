#include "panic_state.h"

#include <utility>

namespace robotalk {

bool PanicState::in_panic() const {
  std::lock_guard lock(mutex_);
  return panic_;
}

bool PanicState::faulted() const {
  std::lock_guard lock(mutex_);
  return faulted_;
}

bool PanicState::has_reason() const {
  std::lock_guard lock(mutex_);
  return !reason_.empty();
}

std::string PanicState::reason() const {
  std::lock_guard lock(mutex_);
  return reason_;
}

std::string PanicState::last_fault() const {
  std::lock_guard lock(mutex_);
  return last_fault_;
}

bool PanicState::driver_halted() const {
  std::lock_guard lock(mutex_);
  return halted_;
}

bool PanicState::requests_pending() const {
  std::lock_guard lock(mutex_);
  return halt_requested_ || resume_requested_;
}

bool PanicState::Raise(const std::string& reason) {
  std::lock_guard lock(mutex_);
  const bool first = !panic_;
  panic_ = true;
  if (!reason.empty()) reason_ = reason;
  // Asked for even if halted: a reset that follows before the RobotDaemon's
  // next iteration still halts once, then resumes.
  halt_requested_ = true;
  return first;
}

bool PanicState::Reset() {
  std::lock_guard lock(mutex_);
  if (!panic_) return false;
  panic_ = false;
  faulted_ = false;
  reason_.clear();
  resume_requested_ = true;
  return true;
}

bool PanicState::Fault(const std::string& what) {
  std::lock_guard lock(mutex_);
  panic_ = true;
  faulted_ = true;
  reason_ = what;
  last_fault_ = what;
  return !std::exchange(halted_, true);
}

bool PanicState::BeginHalt() {
  std::lock_guard lock(mutex_);
  const bool wanted = std::exchange(halt_requested_, false) || panic_;
  return wanted && !std::exchange(halted_, true);
}

bool PanicState::BeginResume() {
  std::lock_guard lock(mutex_);
  if (!std::exchange(resume_requested_, false) || !halted_ || panic_) return false;
  halted_ = false;
  return true;
}

}  // namespace robotalk

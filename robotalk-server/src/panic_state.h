// A robot's panic, halt and driver fault as one small state machine (issue
// 20): what was in nine fields of the RobotDaemon behind two locks and three
// atomics. It does no I/O: the ServerDaemon mirrors it to the panic latch file
// from one place (ServerDaemon::Drain, panic_latch.h).
//
// Two facts, kept apart because different threads change them:
// - panic (with its reason): raised by a client, an overrunning driver call
//   or the latch at start-up (Raise), or by a driver fault the RobotDaemon
//   saw (Fault); cleared only by PANIC_RESET (Reset);
// - whether the driver is halted: the RobotDaemon halts it once in panic
//   (BeginHalt, or at once in Fault) and resumes it once reset (BeginResume).
//
//   running --Raise/Fault--> panic, not halted --BeginHalt--> panic, halted
//   panic, halted --Reset--> reset, halted --BeginResume--> running
//   (Fault halts at once; a Resume that throws is a Fault: halted again.)
//
// Thread safety: every member may be called from any thread; one small lock
// is held only to copy fields (never across a driver call or I/O). Nothing
// allocates except reason() / last_fault() and a Fault's text.
#pragma once

#include <mutex>
#include <string>

namespace robotalk {

class PanicState {
 public:
  PanicState() = default;
  PanicState(const PanicState&) = delete;
  PanicState& operator=(const PanicState&) = delete;

  bool in_panic() const;
  /// In panic because of a driver fault the RobotDaemon saw (Fault), not a
  /// client's panic, an overrun or the latch.
  bool faulted() const;
  /// In panic with a reason (a fault, an overrun, the latch at start-up):
  /// reason() without allocating.
  bool has_reason() const;
  /// Why the robot is in panic: "" for a client's panic, else the fault.
  std::string reason() const;
  /// The text of the last Fault(), kept across a reset ("" before any).
  std::string last_fault() const;
  /// The driver is halted (or a Halt was started and threw).
  bool driver_halted() const;
  /// A halt or resume was asked for since the last BeginHalt/BeginResume.
  bool requests_pending() const;

  // --- transitions ----------------------------------------------------------
  /// Panic, effective at once: nothing but a STOP runs from here on. A
  /// non-empty `reason` (an overrun, the latch at start-up) becomes reason();
  /// an empty one (a client) keeps an earlier fault's. Returns whether the
  /// robot was not in panic before.
  bool Raise(const std::string& reason = {});
  /// PANIC_RESET: clears panic, reason and fault and asks for a resume.
  /// Returns false (and changes nothing) when the robot was not in panic.
  bool Reset();
  /// A driver fault: panic with `what` as the reason. Returns true when the
  /// caller must halt the driver now (it was not halted; it counts as halted
  /// from here on).
  bool Fault(const std::string& what);
  /// At an iteration's start: true when the driver must be halted (in panic
  /// or a halt was asked for, and not halted yet); it counts as halted then.
  bool BeginHalt();
  /// Then: true when the driver must be resumed (a reset since, halted, and
  /// not in panic again); it counts as running then.
  bool BeginResume();

 private:
  mutable std::mutex mutex_;
  bool panic_ = false;             // GUARDED_BY(mutex_)
  bool faulted_ = false;           // GUARDED_BY(mutex_)
  bool halted_ = false;            // GUARDED_BY(mutex_)
  bool halt_requested_ = false;    // GUARDED_BY(mutex_)
  bool resume_requested_ = false;  // GUARDED_BY(mutex_)
  std::string reason_;             // GUARDED_BY(mutex_)
  std::string last_fault_;         // GUARDED_BY(mutex_)
};

}  // namespace robotalk

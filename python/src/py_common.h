// Helpers shared by the binding files (and py_text.h, the one way a text
// crosses into Python): times (seconds as float or
// datetime.timedelta <-> std::chrono), numpy copies of vectors, and the one
// way a binding waits for a reply (GIL released, signals checked).
#pragma once

#include "py_text.h"
#include "robotalk/clock.h"
#include "robotalk/command.h"
#include "robotalk/robot_client.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <chrono>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace robotalk::python {

namespace py = pybind11;

/// A duration from Python: a number of seconds or a datetime.timedelta.
/// Throws robotalk.RobotalkError naming `what` for NaN, infinities or a
/// value out of range, TypeError for anything else.
Duration ToDuration(py::handle value, const char* what);
/// ToDuration, and refuses a negative value (robotalk.UsageError naming `what`).
Duration ToNonNegativeDuration(py::handle value, const char* what);
/// A time on the server clock from seconds (as server_now() returns them).
TimePoint ToTimePoint(double seconds, const char* what);
inline double Seconds(Duration d) { return ToSeconds(d); }
inline double Seconds(TimePoint t) { return ToSeconds(t.time_since_epoch()); }

/// A copy as a 1-D numpy float64 array.
py::array_t<double> ToArray(const std::vector<double>& v);
/// A 1-D float sequence (list, tuple, numpy array) as a vector; every value
/// finite, else robotalk.UsageError naming `what` and the index.
std::vector<double> ToValues(py::handle values, const char* what);

/// How often a wait with the GIL released wakes to run Python's signal
/// handlers (Ctrl-C): the longest a KeyboardInterrupt waits to be raised. A
/// reply wakes the wait at once, whatever this is.
inline constexpr Duration kSignalCheckInterval = std::chrono::milliseconds(50);

/// The one wait of the bindings: calls `attempt(slice)` with the GIL released
/// (it waits at most `slice` for its value) until it returns a value,
/// `finished()` says no value will come, or `most` passed (nullopt: no
/// limit); between attempts, with the GIL, it runs Python's signal handlers
/// every kSignalCheckInterval, throwing pybind11::error_already_set for what
/// they raise (KeyboardInterrupt). REQUIRES: the GIL is held.
template <typename T, typename Attempt, typename Finished>
std::optional<T> WaitInSlices(std::optional<Duration> most, Attempt&& attempt, Finished&& finished) {
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    Duration slice = kSignalCheckInterval;
    if (most) {
      const Duration left = *most - (std::chrono::steady_clock::now() - start);
      slice = std::clamp(left, Duration::zero(), kSignalCheckInterval);
    }
    std::optional<T> value;
    {
      py::gil_scoped_release release;
      value = attempt(slice);
    }
    if (value || finished()) return value;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (most && std::chrono::steady_clock::now() - start >= *most) return std::nullopt;
  }
}

/// Waits for `pending` with the GIL released, at most `most` (nullopt: until
/// the reply or the client gives up on it), waking every
/// kSignalCheckInterval to run Python's signal handlers: a KeyboardInterrupt
/// (or whatever a handler raises) is thrown as pybind11::error_already_set.
/// nullopt when `most` passed. Throws as PendingReply::WaitFor does.
/// REQUIRES: the GIL is held.
/// `guard`, if given, is held (GIL released) around each PendingReply call:
/// a PendingReply is not thread-safe, a Python object may be shared.
std::optional<Reply> WaitInterruptibly(PendingReply& pending, std::optional<Duration> most,
                                       std::mutex* guard = nullptr);

/// The TimeoutError of a wait that got no reply, with the C++
/// PendingReply::Wait's message: "GOTO (id 12): no reply within 5.000000 s".
TimeoutError NoReply(const std::string& what, CommandId id, Duration waited);

/// "GOTO", "JOINT_SETPOINT 'pan'" (as the C++ client names a call in messages).
std::string Describe(const Command& c);

}  // namespace robotalk::python

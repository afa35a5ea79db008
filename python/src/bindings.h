// The pieces of the _robotalk module (module.cpp calls each Bind*), and the
// binding types more than one file constructs.
#pragma once

#include "py_common.h"
#include "robotalk/robot_client.h"

#include <pybind11/pybind11.h>

#include <mutex>
#include <optional>
#include <string>

namespace robotalk::python {

void BindSpec(py::module_& m);    // spec_bindings.cpp
void BindValues(py::module_& m);  // value_bindings.cpp
void BindClient(py::module_& m);  // client_bindings.cpp
void BindLogs(py::module_& m);    // logplay_bindings.cpp

/// robotalk.PendingReply: a non-blocking call's reply, future-like. Unlike
/// the C++ PendingReply it may be shared between Python threads (a mutex
/// serialises the calls, taken with the GIL released).
class PyPendingReply {
 public:
  PyPendingReply(PendingReply pending, std::string what)
      : pending_(std::move(pending)), what_(std::move(what)) {}

  CommandId id() const { return pending_.id(); }
  const std::string& what() const { return what_; }
  /// The reply if it has arrived, else nullopt; throws if the client gave up on it.
  std::optional<Reply> Poll();
  /// Waits (GIL released, Ctrl-C honoured) at most `timeout` (nullopt: until
  /// the reply or the client gives up). Throws TimeoutError.
  Reply Wait(std::optional<Duration> timeout);
  /// As Wait, but nullopt instead of TimeoutError when `most` passes.
  std::optional<Reply> WaitFor(Duration most);
  /// The reply has arrived or the client gave up on it.
  bool Done();

 private:
  std::mutex mu_;
  PendingReply pending_;  // GUARDED_BY(mu_)
  std::string what_;
};

}  // namespace robotalk::python

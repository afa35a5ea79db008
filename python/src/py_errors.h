// The Python exceptions of the robotalk package, mapped from the C++
// hierarchy (robotalk/error.h, robotalk/client_errors.h, robotalk/sequence_file.h,
// tools/logplay's LogError) with the same messages (decoded by Text(), py_text.h:
// a byte that is not UTF-8 shows as \xNN):
//
//   RobotalkError(Exception)                    robotalk::Error
//     ModelError, UrdfError, ProtocolError, TransportError, PanicRefusedError,
//     ClientError, LogError                     the C++ class of the same name
//     LookupError(RobotalkError, LookupError)   robotalk::LookupError
//     UsageError(RobotalkError, ValueError)     robotalk::UsageError (a bad command text)
//     TimeoutError(RobotalkError, TimeoutError) robotalk::TimeoutError
//       UnknownOutcomeError(TimeoutError)       robotalk::UnknownOutcomeError
//     SignalError(RobotalkError)                Python only: a query whose
//                                               data was asked for answered
//                                               another signal (.reply holds it)
//
// A robotalk exception never escapes as RuntimeError: the translator
// registered here catches the most derived C++ class first.
#pragma once

#include "py_text.h"

#include <pybind11/pybind11.h>

namespace robotalk::python {

/// Creates the exception classes in `m` and registers their translator.
void RegisterErrors(pybind11::module_& m);

/// Raises robotalk.SignalError(message) with `reply` (a bound robotalk.Reply)
/// as its .reply attribute. Throws pybind11::error_already_set.
[[noreturn]] void ThrowSignalError(const std::string& message, pybind11::object reply);

}  // namespace robotalk::python

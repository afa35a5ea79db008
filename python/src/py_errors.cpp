// The exception classes and their translator (py_errors.h).
#include "py_errors.h"

#include "robotalk/client_errors.h"
#include "robotalk/error.h"
#include "robotalk/sequence_file.h"
#include "session_log.h"

#include <string>

namespace py = pybind11;

namespace robotalk::python {
namespace {

// Owned by the module (set once at import, under the GIL).
struct Classes {
  PyObject* error = nullptr;
  PyObject* model = nullptr;
  PyObject* urdf = nullptr;
  PyObject* protocol = nullptr;
  PyObject* transport = nullptr;
  PyObject* lookup = nullptr;
  PyObject* usage = nullptr;
  PyObject* timeout = nullptr;
  PyObject* unknown_outcome = nullptr;
  PyObject* panic_refused = nullptr;
  PyObject* client = nullptr;
  PyObject* log = nullptr;
  PyObject* signal = nullptr;
};
Classes classes;

// `cls` with e's message as Text() decodes it. (PyErr_SetString decodes
// strictly: a message holding a byte that is not UTF-8 raised the class
// with its text lost, a UnicodeDecodeError as its context.)
void Raise(PyObject* cls, const std::exception& e) { PyErr_SetObject(cls, Text(e.what()).ptr()); }

PyObject* Make(py::module_& m, const char* name, py::handle bases, const char* doc) {
  const std::string full = std::string("robotalk.") + name;
  PyObject* cls = PyErr_NewExceptionWithDoc(full.c_str(), doc, bases.ptr(), nullptr);
  if (!cls) throw py::error_already_set();
  m.add_object(name, py::handle(cls));  // the module keeps a reference
  return cls;
}

}  // namespace

void RegisterErrors(py::module_& m) {
  py::handle base(classes.error = Make(m, "RobotalkError", PyExc_Exception,
                                       "Base of every exception robotalk raises (C++ robotalk::Error)."));
  auto one = [&](const char* name, const char* doc) { return Make(m, name, base, doc); };
  classes.model =
      one("ModelError", "A robot model is inconsistent (not a tree, duplicate name, bad limit, ...).");
  classes.urdf = one("UrdfError", "A URDF file could not be read, parsed or imported.");
  classes.protocol = one("ProtocolError", "A message is malformed, truncated or of an unsupported version.");
  classes.transport = one("TransportError", "LCM (or a log file) could not start, publish or read.");
  classes.panic_refused = one("PanicRefusedError",
                              "The server answered a panic and did NOT act on it (the robot is not in "
                              "panic because of this call); the message names the reason.");
  classes.client = one("ClientError",
                       "The client cannot do what was asked: not connected, already connected, "
                       "LCM could not be initialised, a package too large, or the client is closed.");
  classes.log = one("LogError", "An LCM log cannot be used as asked (no such client, mixed clocks, ...).");
  classes.signal = one("SignalError",
                       "A query whose data was asked for was answered with another signal than "
                       "SUCCESS or MODIFIED; .reply is the Reply.");
  classes.lookup = Make(m, "LookupError", py::make_tuple(base, py::handle(PyExc_LookupError)),
                        "A name or index does not exist in a robot model.");
  classes.usage = Make(m, "UsageError", py::make_tuple(base, py::handle(PyExc_ValueError)),
                       "A malformed command text or sequence file; the message names the line.");
  classes.timeout = Make(m, "TimeoutError", py::make_tuple(base, py::handle(PyExc_TimeoutError)),
                         "A blocking call did not get its answer in time (the message names the call, "
                         "the id or robot and the time waited).");
  classes.unknown_outcome = Make(m, "UnknownOutcomeError", py::handle(classes.timeout),
                                 "The client cannot tell whether a command ran (it gave up retransmitting, "
                                 "or the server restarted). Ask RobotClient.command_status(id) or re-plan "
                                 "from the robot's state.");

  py::register_exception_translator([](std::exception_ptr p) {
    if (!p) return;
    try {
      std::rethrow_exception(p);
    } catch (const UnknownOutcomeError& e) {
      Raise(classes.unknown_outcome, e);
    } catch (const TimeoutError& e) {
      Raise(classes.timeout, e);
    } catch (const PanicRefusedError& e) {
      Raise(classes.panic_refused, e);
    } catch (const ClientError& e) {
      Raise(classes.client, e);
    } catch (const ModelError& e) {
      Raise(classes.model, e);
    } catch (const UrdfError& e) {
      Raise(classes.urdf, e);
    } catch (const ProtocolError& e) {
      Raise(classes.protocol, e);
    } catch (const TransportError& e) {
      Raise(classes.transport, e);
    } catch (const LookupError& e) {
      Raise(classes.lookup, e);
    } catch (const UsageError& e) {
      Raise(classes.usage, e);
    } catch (const logplay::LogError& e) {
      Raise(classes.log, e);
    } catch (const Error& e) {
      Raise(classes.error, e);
    }
  });
}

void ThrowSignalError(const std::string& message, py::object reply) {
  py::object error = py::reinterpret_borrow<py::object>(classes.signal)(message);
  error.attr("reply") = std::move(reply);
  PyErr_SetObject(classes.signal, error.ptr());
  throw py::error_already_set();
}

}  // namespace robotalk::python

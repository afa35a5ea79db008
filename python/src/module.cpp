// The compiled part of the robotalk Python package (docs/python.md). The
// pure-Python layer (robotalk/__init__.py) imports it as robotalk._robotalk.
#include "bindings.h"
#include "py_errors.h"

PYBIND11_MODULE(_robotalk, m) {
  m.doc() = "RoboTalk's C++ client, motion specification and log reader (bindings; use `import robotalk`).";
  robotalk::python::RegisterErrors(m);
  robotalk::python::BindSpec(m);
  robotalk::python::BindValues(m);
  robotalk::python::BindClient(m);
  robotalk::python::BindLogs(m);
}

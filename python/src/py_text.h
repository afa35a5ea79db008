// The one way a C++ text crosses into Python. Texts come from the wire (a
// reply's message, which anyone can forge in open mode; a command's target; a
// model's names from CONFIG; a log's channels) and need not be UTF-8, so
// each is decoded as UTF-8 with "backslashreplace": a byte that is not part
// of valid UTF-8 reaches Python as the four characters \xNN, never as
// UnicodeDecodeError (nor as an exception whose text is lost).
//
// Two paths, both here:
//   - every std::string a binding returns or py::cast()s (values, reprs,
//     dicts, lists, an exception's constructor argument): the type_caster
//     below, which replaces pybind11's strict one for std::string;
//   - every other text handed to the C API (an exception's message in
//     py_errors.cpp, a dict key): Text().
//
// REQUIRES: included before anything converts a std::string in every file
// of the module (py_common.h and py_errors.h include it; each binding file
// includes one of them), else that file would use pybind11's strict caster.
#pragma once

#include <pybind11/pybind11.h>

#include <string>
#include <string_view>

namespace robotalk::python {

/// `text` as a Python str: UTF-8, each byte that is not valid UTF-8 as \xNN.
inline pybind11::str Text(std::string_view text) {
  PyObject* s = PyUnicode_DecodeUTF8(text.data(), static_cast<Py_ssize_t>(text.size()), "backslashreplace");
  if (!s) throw pybind11::error_already_set();  // only MemoryError: backslashreplace never fails
  return pybind11::reinterpret_steal<pybind11::str>(s);
}

}  // namespace robotalk::python

namespace pybind11::detail {

/// std::string -> str by Text(); str / bytes -> std::string as pybind11 does.
template <>
struct type_caster<std::string> : string_caster<std::string> {
  static handle cast(const std::string& src, return_value_policy /*policy*/, handle /*parent*/) {
    return robotalk::python::Text(src).release();
  }
};

}  // namespace pybind11::detail

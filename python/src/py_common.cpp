// Times, arrays and the interruptible wait (py_common.h).
#include "py_common.h"

#include "robotalk/sequence_file.h"

#include <algorithm>
#include <cmath>

namespace robotalk::python {

Duration ToDuration(py::handle value, const char* what) {
  double s = 0;
  if (py::hasattr(value, "total_seconds")) {
    s = value.attr("total_seconds")().cast<double>();
  } else if (PyFloat_Check(value.ptr()) || PyLong_Check(value.ptr()) || PyNumber_Check(value.ptr())) {
    s = value.cast<double>();
  } else {
    throw py::type_error(std::string(what) + ": expected seconds (a number) or a datetime.timedelta, got " +
                         std::string(py::str(py::type::of(value).attr("__name__"))));
  }
  try {
    return FromSeconds(s);
  } catch (const Error& e) {
    throw Error(std::string(what) + ": " + e.what());
  }
}

Duration ToNonNegativeDuration(py::handle value, const char* what) {
  const Duration d = ToDuration(value, what);
  if (d < Duration::zero()) {
    throw UsageError(std::string(what) + ": " + std::to_string(Seconds(d)) + " s is negative");
  }
  return d;
}

TimePoint ToTimePoint(double seconds, const char* what) {
  try {
    return TimePoint(FromSeconds(seconds));
  } catch (const Error& e) {
    throw Error(std::string(what) + ": " + e.what());
  }
}

py::array_t<double> ToArray(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

std::vector<double> ToValues(py::handle values, const char* what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
  if (!a || a.ndim() > 1) {
    throw UsageError(std::string(what) + ": expected a 1-D sequence of numbers, got " +
                     std::string(py::str(py::repr(values))));
  }
  std::vector<double> v(a.data(), a.data() + a.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      throw UsageError(std::string(what) + ": value " + std::to_string(i) + " is " + std::to_string(v[i]) +
                       ", not a finite number");
    }
  }
  return v;
}

std::optional<Reply> WaitInterruptibly(PendingReply& pending, std::optional<Duration> most,
                                       std::mutex* guard) {
  return WaitInSlices<Reply>(
      most,
      [&](Duration slice) {
        std::unique_lock<std::mutex> lock;
        if (guard) lock = std::unique_lock(*guard);
        return pending.WaitFor(slice);
      },
      [] { return false; });
}

TimeoutError NoReply(const std::string& what, CommandId id, Duration waited) {
  return TimeoutError(what + " (id " + std::to_string(id) + "): no reply within " +
                      std::to_string(Seconds(waited)) + " s");
}

std::string Describe(const Command& c) {
  std::string s = ToString(c.type);
  if (!c.target.empty()) s += " '" + c.target + "'";
  return s;
}

}  // namespace robotalk::python

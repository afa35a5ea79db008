// OdeDriverOptions: parsing of the driver's key=value options and checks.
#include "ode_driver.h"
#include "robotalk/driver_support.h"
#include "robotalk/error.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace robotalk {
namespace {

[[noreturn]] void BadOption(const std::string& key, const std::string& value, const char* expected) {
  throw Error("ode driver: option " + key + "='" + value + "': expected " + expected);
}

double ParseNumber(const std::string& key, const std::string& value, double min, bool min_inclusive,
                   const char* expected) {
  const char* begin = value.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (value.empty() || end != begin + value.size() || !std::isfinite(v) || v < min ||
      (!min_inclusive && v == min)) {
    BadOption(key, value, expected);
  }
  return v;
}

std::vector<std::string> SplitPlus(const std::string& s) {
  std::vector<std::string> out;
  size_t start = 0;
  while (start <= s.size() && !s.empty()) {
    const size_t plus = s.find('+', start);
    const std::string part = s.substr(start, plus == std::string::npos ? std::string::npos : plus - start);
    if (!part.empty()) out.push_back(part);
    if (plus == std::string::npos) break;
    start = plus + 1;
  }
  return out;
}

using driver_support::Num;

}  // namespace

OdeDriverOptions OdeDriverOptions::FromMap(const std::map<std::string, std::string>& options) {
  OdeDriverOptions o;
  for (const auto& [key, value] : options) {
    if (key == "step_hz") {
      o.step_hz = ParseNumber(key, value, 0, false, "a rate > 0 (Hz)");
    } else if (key == "period_ms") {
      o.period = FromSeconds(ParseNumber(key, value, 0, false, "a number of milliseconds > 0") / 1000.0);
      if (o.period <= Duration::zero()) BadOption(key, value, "a number of milliseconds > 0");
    } else if (key == "gravity") {
      o.gravity = ParseNumber(key, value, 0, true, "an acceleration >= 0 (m/s^2)");
    } else if (key == "friction") {
      o.friction = ParseNumber(key, value, 0, true, "a friction coefficient >= 0");
    } else if (key == "seed") {
      const double s = ParseNumber(key, value, 0, true, "an integer in [0, 4294967295]");
      if (s != std::floor(s) || s > 4294967295.0) BadOption(key, value, "an integer in [0, 4294967295]");
      o.seed = static_cast<std::uint32_t>(s);
    } else if (key == "solver") {
      if (value != "step" && value != "quickstep") BadOption(key, value, "step or quickstep");
      o.solver = value;
    } else if (key == "kp") {
      o.kp = ParseNumber(key, value, 0, false, "a gain > 0 (1/s)");
    } else if (key == "default_velocity") {
      o.default_velocity = ParseNumber(key, value, 0, false, "a speed > 0 (rad/s or m/s)");
    } else if (key == "default_effort") {
      o.default_effort = ParseNumber(key, value, 0, false, "an effort > 0 (N m or N)");
    } else if (key == "base_max_v") {
      o.base_max_v = ParseNumber(key, value, 0, false, "a speed > 0 (m/s)");
    } else if (key == "base_max_omega") {
      o.base_max_omega = ParseNumber(key, value, 0, false, "a yaw rate > 0 (rad/s)");
    } else if (key == "goto_tolerance") {
      o.goto_tolerance = ParseNumber(key, value, 0, false, "a distance > 0 (m)");
    } else if (key == "goto_heading_tolerance") {
      o.goto_heading_tolerance = ParseNumber(key, value, 0, false, "an angle > 0 (rad)");
    } else if (key == "left_wheel") {
      o.left_wheel = value;
    } else if (key == "right_wheel") {
      o.right_wheel = value;
    } else if (key == "wheel_radius") {
      o.wheel_radius = ParseNumber(key, value, 0, true, "a radius >= 0 (m; 0 = from the model)");
    } else if (key == "wheel_separation") {
      o.wheel_separation = ParseNumber(key, value, 0, true, "a distance >= 0 (m; 0 = from the model)");
    } else if (key == "casters") {
      o.casters = SplitPlus(value);
    } else if (key == "base") {
      if (value != "fixed" && value != "differential" && value != "holonomic" && value != "floating") {
        BadOption(key, value, "fixed, differential, holonomic or floating");
      }
      o.base = value;
    } else if (key == "merge_chains") {
      const std::optional<bool> b = driver_support::ParseBool(value);
      if (!b) BadOption(key, value, "true or false");
      o.merge_chains = *b;
    } else if (key == "walk") {
      const std::optional<bool> b = driver_support::ParseBool(value);
      if (!b) BadOption(key, value, "true or false");
      o.walk = *b;
    } else if (key == "max_catchup_ms") {
      o.max_catchup_ms = ParseNumber(key, value, 0, false, "a number of milliseconds > 0");
    } else if (key == "virtual_mass") {
      o.virtual_mass = ParseNumber(key, value, 0, false, "a mass > 0 (kg)");
    } else if (key == "gait_joints") {
      if (SplitPlus(value).size() != 4) BadOption(key, value, "left_hip+left_knee+right_hip+right_knee");
      o.gait_joints = value;
    } else {
      throw Error(
          "ode driver: unknown option '" + key +
          "' (known: base, base_max_omega, base_max_v, casters, default_effort, default_velocity, friction, "
          "gait_joints, goto_heading_tolerance, goto_tolerance, gravity, kp, left_wheel, max_catchup_ms, "
          "merge_chains, period_ms, right_wheel, seed, solver, step_hz, virtual_mass, walk, "
          "wheel_radius, wheel_separation)");
    }
  }
  return o;
}

void OdeDriverOptions::Validate() const {
  auto positive = [](const char* name, double v) {
    if (!std::isfinite(v) || v <= 0)
      throw Error(std::string("OdeDriver: ") + name + " = " + Num(v) + ", expected > 0");
  };
  auto non_negative = [](const char* name, double v) {
    if (!std::isfinite(v) || v < 0)
      throw Error(std::string("OdeDriver: ") + name + " = " + Num(v) + ", expected >= 0");
  };
  positive("step_hz", step_hz);
  if (period <= Duration::zero())
    throw Error("OdeDriver: period = " + Num(ToSeconds(period)) + " s, expected > 0");
  non_negative("gravity", gravity);
  non_negative("friction", friction);
  positive("kp", kp);
  positive("default_velocity", default_velocity);
  positive("default_effort", default_effort);
  positive("base_max_v", base_max_v);
  positive("base_max_omega", base_max_omega);
  positive("goto_tolerance", goto_tolerance);
  positive("goto_heading_tolerance", goto_heading_tolerance);
  non_negative("wheel_radius", wheel_radius);
  non_negative("wheel_separation", wheel_separation);
  positive("max_catchup_ms", max_catchup_ms);
  positive("virtual_mass", virtual_mass);
  if (solver != "step" && solver != "quickstep")
    throw Error("OdeDriver: solver = '" + solver + "', expected step or quickstep");
}

}  // namespace robotalk

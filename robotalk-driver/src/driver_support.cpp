#include "robotalk/driver_support.h"

#include "robotalk/error.h"
#include "robotalk/sequence_file.h"  // NumberOf

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>

namespace robotalk::driver_support {

DriverResult Answer(Signal signal, std::string message) {
  return DriverResult{.signal = signal, .in_progress = false, .message = std::move(message)};
}

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

const char* Unit(DofType t) { return t == DofType::kRevolute ? "rad" : "m"; }

std::string Quote(const std::string& name) { return "'" + name + "'"; }

DriverResult NotExecuted(const DriverCommand& c, const std::string& driver) {
  const std::string name = ToString(c.type);
  if (!IsMotionCommand(c.type))
    return Answer(Signal::kError, name + " is not a motion command a driver executes");
  return Answer(Signal::kNa, name + ": " + driver + " does not execute it");
}

Eigen::Vector3d FrameGoalPosition(const DriverCommand& c) { return {c.values[0], c.values[1], c.values[2]}; }

Eigen::Quaterniond FrameGoalOrientation(const DriverCommand& c) {
  return Eigen::Quaterniond(c.values[3], c.values[4], c.values[5], c.values[6]);
}

std::optional<DriverResult> CheckFrameSetPoint(const RobotModel& model, const InverseKinematics& ik,
                                               const DriverCommand& c) {
  if (c.target < 0 || c.target >= static_cast<int>(model.frames().size())) {
    return Answer(Signal::kError, "FRAME_SETPOINT: no control frame with index " + std::to_string(c.target));
  }
  if (c.num_values != 7) {
    return Answer(Signal::kError, "FRAME_SETPOINT: expected 7 values (x y z qw qx qy qz), got " +
                                      std::to_string(c.num_values));
  }
  const ControlFrame& frame = model.frame(c.target);
  if (!ik.HasMovableDofs(c.target)) {
    return Answer(Signal::kNa, "FRAME_SETPOINT " + Quote(frame.name) +
                                   ": no joint between the frame and its root accepts set-points");
  }
  const double norm = FrameGoalOrientation(c).norm();
  if (!(norm > 1e-9) || !std::isfinite(norm)) {  // CheckCommand wants a unit quaternion; a driver re-checks
    return Answer(Signal::kError, "FRAME_SETPOINT " + Quote(frame.name) +
                                      ": orientation quaternion has norm " + Num(norm) + ", expected 1");
  }
  return std::nullopt;
}

DriverResult AnswerFrameSetPoint(const std::string& frame, const InverseKinematics::Result& r) {
  if (r.within_tolerance) return Answer(Signal::kSuccess);
  return Answer(Signal::kModified,
                "FRAME_SETPOINT " + Quote(frame) + ": pose not reachable; moving to the closest found, " +
                    Num(r.position_error) + " m and " + Num(r.orientation_error) + " rad away");
}

std::optional<bool> ParseBool(const std::string& value) {
  if (value == "true" || value == "1") return true;
  if (value == "false" || value == "0") return false;
  return std::nullopt;
}

BaseTwist ShapeBaseSpeed(const DriverCommand& c, BaseType base, double max_v, double max_omega) {
  BaseTwist t;
  t.vx = c.values[0];
  t.vy = c.num_values == 3 ? c.values[1] : 0.0;
  t.omega = c.values[static_cast<size_t>(c.num_values - 1)];
  if (t.vy != 0 && base == BaseType::kDifferential) {
    t.Note("lateral speed vy = " + Num(t.vy) + " m/s dropped (differential base)");
    t.vy = 0;
  }
  const double planar = std::hypot(t.vx, t.vy);
  if (planar > max_v) {
    t.Note("speed " + Num(planar) + " m/s clamped to base_max_v " + Num(max_v) + " m/s");
    t.vx *= max_v / planar;
    t.vy *= max_v / planar;
  }
  if (std::abs(t.omega) > max_omega) {
    t.Note("yaw rate " + Num(t.omega) + " rad/s clamped to base_max_omega " + Num(max_omega) + " rad/s");
    t.omega = std::copysign(max_omega, t.omega);
  }
  return t;
}

DriverCommand SetSpeedOf(const BaseReference& reference) {
  DriverCommand speed;
  speed.type = CommandType::kSetSpeed;
  const bool lateral = reference.lateral || reference.vy != 0.0;
  speed.num_values = lateral ? 3 : 2;
  speed.values = {reference.vx, lateral ? reference.vy : reference.omega, reference.omega};
  return speed;
}

double WrapAngle(double radians) { return std::remainder(radians, 2 * std::numbers::pi); }

OptionReader::OptionReader(std::string driver, const std::map<std::string, std::string>& options)
    : driver_(std::move(driver)), options_(options) {}

void OptionReader::Fail(const std::string& key, const char* expected) const {
  auto it = options_.find(key);
  throw Error(driver_ + ": option " + key + "='" + (it == options_.end() ? "" : it->second) + "': expected " +
              expected);
}

void OptionReader::Number(const std::string& key, double* out, Range range, const char* expected) {
  known_.insert(key);
  auto it = options_.find(key);
  if (it == options_.end()) return;
  const std::optional<double> parsed = NumberOf(it->second);  // the one rule of every number option
  if (!parsed || !std::isfinite(*parsed)) Fail(key, expected);
  const double v = *parsed;
  if (v < range.min || (!range.min_inclusive && v == range.min) || v > range.max ||
      (range.integer && v != std::floor(v))) {
    Fail(key, expected);
  }
  *out = v;
}

void OptionReader::Milliseconds(const std::string& key, Duration* out) {
  constexpr const char* kExpected = "a number of milliseconds > 0";
  double ms = ToSeconds(*out) * 1000.0;
  Number(key, &ms, {.min = 0, .min_inclusive = false}, kExpected);
  const Duration d = FromSeconds(ms / 1000.0);
  if (d <= Duration::zero()) Fail(key, kExpected);
  *out = d;
}

void OptionReader::Bool(const std::string& key, bool* out) {
  known_.insert(key);
  auto it = options_.find(key);
  if (it == options_.end()) return;
  const std::optional<bool> b = ParseBool(it->second);
  if (!b) Fail(key, "true or false");
  *out = *b;
}

bool OptionReader::Text(const std::string& key, std::string* out) {
  known_.insert(key);
  auto it = options_.find(key);
  if (it == options_.end()) return false;
  *out = it->second;
  return true;
}

void OptionReader::Finish() const {
  for (const auto& [key, value] : options_) {
    if (known_.count(key)) continue;
    std::string known;
    for (const std::string& k : known_) known += (known.empty() ? "" : ", ") + k;
    throw Error(driver_ + ": unknown option '" + key + "' (known: " + known + ")");
  }
}

void CheckPositive(const std::string& owner, const char* name, double v) {
  if (!std::isfinite(v) || v <= 0) throw Error(owner + ": " + name + " = " + Num(v) + ", expected > 0");
}

void CheckNonNegative(const std::string& owner, const char* name, double v) {
  if (!std::isfinite(v) || v < 0) throw Error(owner + ": " + name + " = " + Num(v) + ", expected >= 0");
}

void CheckPeriod(const std::string& owner, Duration period) {
  if (period <= Duration::zero())
    throw Error(owner + ": period = " + Num(ToSeconds(period)) + " s, expected > 0");
}

}  // namespace robotalk::driver_support

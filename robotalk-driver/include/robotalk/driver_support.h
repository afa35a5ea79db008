// Small helpers for driver writers, so every driver answers in the same words
// (docs/drivers.md): results, numbers and names in messages, and the checks
// and answers of a FRAME_SETPOINT solved with InverseKinematics.
#pragma once

#include "robotalk/driver.h"
#include "robotalk/inverse_kinematics.h"

#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>

namespace robotalk::driver_support {

/// A final (not in-progress) result.
DriverResult Answer(Signal signal, std::string message = {});
/// What Execute() answers for a command type the driver has no handler for
/// (the default of its dispatch): NA "<TYPE>: <driver> does not execute it"
/// for a motion command, ERROR for one never sent to a driver (STOP and
/// PANIC_RESET, driver.h). `driver`: "the kinematic driver".
DriverResult NotExecuted(const DriverCommand& command, const std::string& driver);
/// A number in a message: short and exact enough to read ("0.5411").
std::string Num(double v);
/// "rad" or "m".
const char* Unit(DofType t);
/// 'name'
std::string Quote(const std::string& name);

/// Before solving a FRAME_SETPOINT: ERROR for a frame index out of range, a
/// value count other than 7 or a zero or non-finite orientation; NA when no
/// set-point joint moves the frame; nullopt to go on.
std::optional<DriverResult> CheckFrameSetPoint(const RobotModel& model, const InverseKinematics& ik,
                                               const DriverCommand& command);
/// The goal of a FRAME_SETPOINT: x y z and the orientation qw qx qy qz.
Eigen::Vector3d FrameGoalPosition(const DriverCommand& command);
Eigen::Quaterniond FrameGoalOrientation(const DriverCommand& command);
/// "true"/"1" or "false"/"0" of a driver option; nullopt for anything else.
std::optional<bool> ParseBool(const std::string& value);

/// An angle wrapped to (-π, π].
double WrapAngle(double radians);

/// Reads a driver's key=value options (DriverConfig::options) with errors
/// that name the driver, the option, the value and what was expected:
///
///   OptionReader r("kinematic driver", config.options);
///   r.Number("period_ms", &period_ms, {.min = 0, .min_inclusive = false}, "a number of milliseconds > 0");
///   r.Bool("merge_chains", &merge);
///   r.Finish();  // throws naming an unknown key and the known ones
///
/// Each call leaves its output untouched when the key is absent.
class OptionReader {
 public:
  struct Range {
    double min = -std::numeric_limits<double>::infinity();
    bool min_inclusive = true;
    double max = std::numeric_limits<double>::infinity();
    bool integer = false;
  };
  OptionReader(std::string driver, const std::map<std::string, std::string>& options);

  /// A finite number in `range`; throws Error "<driver>: option k='v': expected <expected>".
  void Number(const std::string& key, double* out, Range range, const char* expected);
  /// A time > 0 given in milliseconds (period_ms), kept exact to the
  /// microsecond of a Duration; one that rounds to zero is refused as well:
  /// "<driver>: option k='v': expected a number of milliseconds > 0".
  void Milliseconds(const std::string& key, Duration* out);
  void Bool(const std::string& key, bool* out);
  /// Any text (the caller checks it); returns whether the key was given.
  bool Text(const std::string& key, std::string* out);
  /// Throws Error "[driver]: unknown option 'k' (known: a, b, c)" for a key no call asked for.
  void Finish() const;
  [[noreturn]] void Fail(const std::string& key, const char* expected) const;

 private:
  std::string driver_;
  const std::map<std::string, std::string>& options_;
  std::set<std::string> known_;
};

/// An options struct's Validate(): throws Error "<owner>: <name> = <v>,
/// expected > 0" (">= 0") for a value that is not, NaN and infinities
/// included; `owner` is the class ("KinematicDriver").
void CheckPositive(const std::string& owner, const char* name, double v);
void CheckNonNegative(const std::string& owner, const char* name, double v);
/// Throws Error "<owner>: period = <s> s, expected > 0" for a control period that is not.
void CheckPeriod(const std::string& owner, Duration period);

/// After solving: SUCCESS within the solver's tolerance, else MODIFIED with the residual.
DriverResult AnswerFrameSetPoint(const std::string& frame, const InverseKinematics::Result& result);

/// A SETSPEED request shaped to the base: the lateral speed of a holonomic
/// request dropped on a differential base, the planar speed and the yaw rate
/// clamped to the base's limits. `note` says what was changed ("" = nothing,
/// so SUCCESS; otherwise the driver answers MODIFIED with it).
struct BaseTwist {
  double vx = 0, vy = 0, omega = 0;  ///< m/s, m/s, rad/s in the base frame
  std::string note;
  void Note(const std::string& what) { note += (note.empty() ? "" : "; ") + what; }
};
/// REQUIRES: `command` is a SETSPEED with 2 (v ω) or 3 (vx vy ω) values.
BaseTwist ShapeBaseSpeed(const DriverCommand& command, BaseType base, double max_v, double max_omega);

/// The SETSPEED of a base reference's twist: "vx vy ω" when it is lateral
/// (or vy is not 0), else "v ω" (Driver::TrackBase's default).
DriverCommand SetSpeedOf(const BaseReference& reference);

}  // namespace robotalk::driver_support

// OdeDriverOptions: parsing of the driver's key=value options and checks.
#include "ode_driver.h"
#include "robotalk/driver_support.h"
#include "robotalk/error.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace robotalk {
namespace {

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

}  // namespace

OdeDriverOptions OdeDriverOptions::FromMap(const std::map<std::string, std::string>& options) {
  OdeDriverOptions o;
  using Range = driver_support::OptionReader::Range;
  constexpr Range kPositive{.min = 0, .min_inclusive = false};
  constexpr Range kNonNegative{.min = 0};
  driver_support::OptionReader r("ode driver", options);
  r.Number("step_hz", &o.step_hz, kPositive, "a rate > 0 (Hz)");
  r.Milliseconds("period_ms", &o.period);
  r.Number("gravity", &o.gravity, kNonNegative, "an acceleration >= 0 (m/s^2)");
  r.Number("friction", &o.friction, kNonNegative, "a friction coefficient >= 0");
  double seed = o.seed;
  r.Number("seed", &seed, {.min = 0, .max = 4294967295.0, .integer = true}, "an integer in [0, 4294967295]");
  o.seed = static_cast<std::uint32_t>(seed);
  if (r.Text("solver", &o.solver) && o.solver != "step" && o.solver != "quickstep") {
    r.Fail("solver", "step or quickstep");
  }
  r.Number("kp", &o.kp, kPositive, "a gain > 0 (1/s)");
  r.Number("default_velocity", &o.default_velocity, kPositive, "a speed > 0 (rad/s or m/s)");
  r.Number("default_effort", &o.default_effort, kPositive, "an effort > 0 (N m or N)");
  r.Number("base_max_v", &o.base_max_v, kPositive, "a speed > 0 (m/s)");
  r.Number("base_max_omega", &o.base_max_omega, kPositive, "a yaw rate > 0 (rad/s)");
  r.Number("goto_tolerance", &o.goto_tolerance, kPositive, "a distance > 0 (m)");
  r.Number("goto_heading_tolerance", &o.goto_heading_tolerance, kPositive, "an angle > 0 (rad)");
  r.Text("left_wheel", &o.left_wheel);
  r.Text("right_wheel", &o.right_wheel);
  r.Number("wheel_radius", &o.wheel_radius, kNonNegative, "a radius >= 0 (m; 0 = from the model)");
  r.Number("wheel_separation", &o.wheel_separation, kNonNegative, "a distance >= 0 (m; 0 = from the model)");
  std::string casters;
  if (r.Text("casters", &casters)) o.casters = SplitPlus(casters);
  if (r.Text("base", &o.base) && o.base != "fixed" && o.base != "differential" && o.base != "holonomic" &&
      o.base != "floating") {
    r.Fail("base", "fixed, differential, holonomic or floating");
  }
  r.Bool("merge_chains", &o.merge_chains);
  r.Bool("walk", &o.walk);
  r.Bool("stabilizer", &o.stabilizer);
  r.Bool("step_adjustment", &o.step_adjustment);
  r.Bool("push_recovery", &o.push_recovery);
  r.Bool("push_capture", &o.push_capture);
  r.Number("push_swing_reach", &o.push_swing_reach, kNonNegative, "a speed >= 0 (m/s; 0: off)");
  r.Number("push_lift_reach", &o.push_lift_reach, kNonNegative, "a speed >= 0 (m/s; 0: off)");
  if (r.Text("push_stop_feet", &o.push_stop_feet) && o.push_stop_feet != "move" &&
      o.push_stop_feet != "keep" && o.push_stop_feet != "still") {
    r.Fail("push_stop_feet", "move, keep or still");
  }
  if (r.Text("push_step_timing", &o.push_step_timing) && o.push_step_timing != "off" &&
      o.push_step_timing != "push" && o.push_step_timing != "threshold" && o.push_step_timing != "always") {
    r.Fail("push_step_timing", "off, push, threshold or always");
  }
  r.Number("push_min_swing", &o.push_min_swing, kNonNegative, "a time >= 0 (s)");
  r.Number("push_stop_wait", &o.push_stop_wait, kNonNegative, "a time >= 0 (s; 0: off)");
  r.Bool("push_stop_land", &o.push_stop_land);
  if (r.Text("push_balance", &o.push_balance) && o.push_balance != "off" && o.push_balance != "both") {
    const std::vector<std::string> parts = SplitPlus(o.push_balance);
    if (parts.empty()) r.Fail("push_balance", "off, both, or damping, stabilizer and forces joined by '+'");
    for (const std::string& part : parts) {
      if (part != "damping" && part != "stabilizer" && part != "forces") {
        r.Fail("push_balance", "off, both, or damping, stabilizer and forces joined by '+'");
        break;
      }
    }
  }
  // push_balance's stabilizer part runs the stabilizer only while a push's
  // stop holds: without an explicit `stabilizer`, it takes the default
  // (always on) off; an explicit stabilizer=true with it is refused (Validate).
  if (!options.contains("stabilizer") &&
      (o.push_balance == "both" || o.push_balance.find("stabilizer") != std::string::npos))
    o.stabilizer = false;
  r.Bool("foot_damping", &o.foot_damping);
  if (r.Text("gait", &o.gait) && o.gait != "fast" && o.gait != "slow") r.Fail("gait", "fast or slow");
  auto& go = o.gait_overrides;
  r.Number("step_length", &go.step_length, kPositive, "a step length > 0 (m)");
  r.Number("step_back", &go.step_back, kPositive, "a step length > 0 (m)");
  r.Number("step_side", &go.step_side, kPositive, "a sideways step > 0 (m)");
  r.Number("step_yaw", &go.step_yaw, kPositive, "a turn per step > 0 (rad)");
  r.Number("single_support", &go.single_support, kPositive, "a duration > 0 (s)");
  r.Number("double_support", &go.double_support, kPositive, "a duration > 0 (s)");
  r.Number("step_height", &go.step_height, kPositive, "a swing height > 0 (m)");
  r.Number("max_catchup_ms", &o.max_catchup_ms, kPositive, "a number of milliseconds > 0");
  r.Number("virtual_mass", &o.virtual_mass, kPositive, "a mass > 0 (kg)");
  if (r.Text("gait_joints", &o.gait_joints) && SplitPlus(o.gait_joints).size() != 4) {
    r.Fail("gait_joints", "left_hip+left_knee+right_hip+right_knee");
  }
  r.Finish();
  return o;
}

void OdeDriverOptions::Validate() const {
  const auto positive = [](const char* name, double v) {
    driver_support::CheckPositive("OdeDriver", name, v);
  };
  const auto non_negative = [](const char* name, double v) {
    driver_support::CheckNonNegative("OdeDriver", name, v);
  };
  positive("step_hz", step_hz);
  driver_support::CheckPeriod("OdeDriver", period);
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
  if (gait != "fast" && gait != "slow")
    throw Error("OdeDriver: gait = '" + gait + "', expected fast or slow");
  for (auto [name, v] : {std::pair{"step_length", gait_overrides.step_length},
                         {"step_back", gait_overrides.step_back},
                         {"step_side", gait_overrides.step_side},
                         {"step_yaw", gait_overrides.step_yaw},
                         {"single_support", gait_overrides.single_support},
                         {"double_support", gait_overrides.double_support},
                         {"step_height", gait_overrides.step_height}}) {
    non_negative(name, v);
  }
  if (solver != "step" && solver != "quickstep")
    throw Error("OdeDriver: solver = '" + solver + "', expected step or quickstep");
  // push_balance's stabilizer runs it only while a push's stop holds: with
  // the stabilizer on all the time it would mean nothing.
  if (stabilizer && (push_balance == "both" || push_balance.find("stabilizer") != std::string::npos)) {
    throw Error("OdeDriver: push_balance=" + push_balance +
                " runs the stabilizer only while a push's stop holds, but stabilizer=true runs it always: "
                "give stabilizer=false with it (or leave stabilizer out: push_balance's stabilizer part "
                "turns the default off), or drop its stabilizer part (e.g. push_balance=damping)");
  }
}

}  // namespace robotalk

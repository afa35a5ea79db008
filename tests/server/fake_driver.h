// A scripted Driver for server tests: records what it was asked, answers
// GOTO as a task that completes after `goto_updates` Update() calls and,
// as the shipped drivers do, SETSPEED with BUSY while a GOTO runs.
#pragma once

#include "robotalk/driver.h"

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace robotalk::testing {

/// base (differential root) -> "pan" (1 revolute dof, limits ±1) -> head.
inline RobotModel PanRobot(BaseType base = BaseType::kDifferential) {
  RobotModelBuilder b("bot");
  Link body{.name = "base", .mass = 1.0};
  body.inertia = Eigen::Matrix3d::Identity() * 0.1;
  Link head{.name = "head", .mass = 0.5};
  head.inertia = Eigen::Matrix3d::Identity() * 0.01;
  b.AddLink(body).AddLink(head);
  Joint pan{.name = "pan"};
  pan.dofs.push_back(
      Dof{.type = DofType::kRevolute, .axis = Eigen::Vector3d::UnitZ(), .limits = {-1, 1, 1, 1}});
  pan.servo_types = ServoType::kSetPoint;
  b.AddJoint(pan, "base", "head");
  b.SetRoot("base", Pose{}, base);
  return b.Build();
}

class FakeDriver : public Driver {
 public:
  struct Call {
    CommandType type;
    TimePoint at;
    std::vector<double> values;
  };

  explicit FakeDriver(RobotModel model) : model_(std::move(model)) {}

  const RobotModel& model() const override { return model_; }
  Duration period() const override { return std::chrono::milliseconds(10); }

  DriverResult Execute(const DriverCommand& c, TimePoint now,
                       std::vector<Completion>& /*completed*/) override {
    calls.push_back({c.type, now, {c.values.begin(), c.values.begin() + c.num_values}});
    if (halted) throw std::logic_error("FakeDriver: Execute while halted breaks the driver contract");
    if (throw_on_execute) throw std::runtime_error(*throw_on_execute);
    switch (c.type) {
      case CommandType::kGoto:
        if (goto_id) return {Signal::kBusy, false, "GOTO in progress"};
        goto_id = c.id;
        updates_left = goto_updates;
        return {Signal::kSuccess, true, ""};
      case CommandType::kSetSpeed:
        if (goto_id) return {Signal::kBusy, false, "SETSPEED: GOTO in progress"};
        return {};
      case CommandType::kJointSetPoint:
        if (std::abs(c.values[0]) > 1) return {Signal::kModified, false, "clamped"};
        position = c.values[0];
        moving = true;
        return {};
      default:
        return {};
    }
  }
  void Stop(TimePoint now, std::vector<Completion>& interrupted) override {
    calls.push_back({CommandType::kStop, now, {}});
    if (goto_id) interrupted.push_back({*goto_id, Signal::kInterrupted, "stopped"});
    goto_id.reset();
    moving = false;
  }
  void StopOnly(const StopScope& scope, TimePoint now, std::vector<Completion>& interrupted) override {
    partial_stops.push_back({now, {scope.joints.begin(), scope.joints.end()}, scope.base});
    if (scope.base && goto_id) interrupted.push_back({*goto_id, Signal::kInterrupted, "stopped"});
    if (scope.base) goto_id.reset();
  }
  void Update(TimePoint, std::vector<Completion>& completed) override {
    ++updates;
    if (goto_id && --updates_left <= 0) {
      completed.push_back({*goto_id, Signal::kSuccess, ""});
      goto_id.reset();
    }
  }
  void ReadState(RobotState& s) const override {
    s.position[0] = position;
    s.velocity[0] = 0.25;
    s.effort[0] = -0.5;
    s.moving = moving;
  }
  void Halt(std::vector<Completion>& interrupted) override {
    halted = true;
    moving = false;
    if (goto_id) interrupted.push_back({*goto_id, Signal::kInterrupted, "halted"});
    goto_id.reset();
  }
  void Resume() override { halted = false; }
  std::string_view Fault() const override { return fault; }

  struct PartialStop {
    TimePoint at;
    std::vector<int> joints;
    bool base = false;
  };

  RobotModel model_;
  std::vector<PartialStop> partial_stops;  // StopOnly() calls (not in `calls`)
  std::string fault;                       // what Fault() reports ("" = none)
  std::vector<Call> calls;
  std::optional<CommandId> goto_id;
  int goto_updates = 3;
  int updates_left = 0;
  int updates = 0;
  double position = 0;
  bool halted = false;
  bool moving = false;
  std::optional<std::string> throw_on_execute;  ///< Execute throws this message
};

}  // namespace robotalk::testing

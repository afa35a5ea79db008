// Issue 22's tracking measurement, shared by tests/drivers/ode_tracking_test.cpp
// and bench/trajectory_bench.cpp: a RobotDaemon on a ManualClock (in-process,
// no network) runs a driver while a delay-mode client streams a sine on one
// joint as timed JOINT_SETPOINT waypoints (QueuedItems with start times and
// an interpolation, submitted `delay` ahead of their times, as the server
// queues a delay-mode client's frames). Every control period the joint's
// measured position is compared with the continuous sine.
// Header-only: needs robotalk::server and the server's src/ on the include path.
#pragma once

#include "observed_driver.h"
#include "robot_daemon.h"
#include "robotalk/clock.h"
#include "robotalk/driver.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

namespace robotalk::testing {

/// Keeps the last reference the server handed to each dof (Driver::Track),
/// so a run can read it beside the state the driver measured.
class ReferenceRecorder final : public DriverObserver {
 public:
  explicit ReferenceRecorder(const RobotModel& model)
      : model_(model),
        position_(static_cast<std::size_t>(model.num_dofs()), NAN),
        velocity_(position_.size(), NAN),
        time_(position_.size(), TimePoint::min()) {}
  void Tracked(const JointReference& r, TimePoint now) override {
    const auto first = static_cast<std::size_t>(model_.dof_offset(r.joint));
    for (std::size_t k = 0; k < r.position.size(); ++k) {
      position_[first + k] = r.position[k];
      velocity_[first + k] = r.velocity[k];
      time_[first + k] = now;
    }
  }
  /// The last reference of dof `i`, and when it was handed over (min: never).
  double ref_position(int i) const { return position_[static_cast<std::size_t>(i)]; }
  double ref_velocity(int i) const { return velocity_[static_cast<std::size_t>(i)]; }
  TimePoint ref_time(int i) const { return time_[static_cast<std::size_t>(i)]; }

 private:
  const RobotModel& model_;
  std::vector<double> position_, velocity_;
  std::vector<TimePoint> time_;
};

/// A RobotDaemon on a ManualClock with an ObservedDriver around `driver`.
class ManualDaemon {
 public:
  static constexpr std::int64_t kClient = 0xC11E;
  static TimePoint Origin() { return TimePoint(std::chrono::seconds(1000)); }

  explicit ManualDaemon(std::unique_ptr<Driver> driver,
                        RobotDaemonOptions options = {.precise_timing = false})
      : recorder_(std::make_shared<ReferenceRecorder>(driver->model())),
        observed_(new ObservedDriver(std::move(driver), recorder_)),
        daemon_("robot", "driver", std::unique_ptr<Driver>(observed_), clock_, options) {
    daemon_.Preallocate(out_);
    state_.position = Eigen::VectorXd::Zero(model().num_dofs());
    state_.velocity = state_.position;
    state_.effort = state_.position;
  }
  const RobotModel& model() const { return observed_->model(); }
  /// The references the driver was handed.
  const ReferenceRecorder& driver() const { return *recorder_; }
  RobotDaemon& daemon() { return daemon_; }
  ManualClock& clock() { return clock_; }
  Duration period() const { return observed_->period(); }

  /// Runs the daemon at every deadline up to `t`, and at `t`; counts the
  /// answers by signal. Reads the driver's state at `t`.
  void RunTo(TimePoint t) {
    while (clock_.Now() < t) {
      clock_.Set(std::min(daemon_.RunOnce(clock_.Now()), t));
      Drain();
    }
    daemon_.RunOnce(clock_.Now());
    Drain();
    observed_->ReadState(state_);
  }
  const RobotState& state() const { return state_; }
  /// Answers so far: SUCCESS, MODIFIED, and every other signal.
  int succeeded = 0, modified = 0, other = 0;
  /// The message of the last answer that was not SUCCESS.
  std::string last_note;
  /// Takes the outbox (the ServerDaemon's side), counting the answers.
  void Drain() {
    daemon_.TakeOutput(out_);
    for (const auto& a : out_.replies) {
      if (a.reply.signal != Signal::kSuccess) last_note = a.reply.message;
      (a.reply.signal == Signal::kSuccess    ? succeeded
       : a.reply.signal == Signal::kModified ? modified
                                             : other)++;
    }
  }

  /// A JOINT_SETPOINT waypoint of joint `joint` at `at` (value `q`).
  static QueuedItem Waypoint(CommandId id, int joint, TimePoint at, double q, Interpolation interpolation) {
    QueuedItem item;
    item.client_id = kClient;
    item.command.id = id;
    item.command.type = CommandType::kJointSetPoint;
    item.command.target = joint;
    item.command.num_values = 1;
    item.command.values[0] = q;
    item.has_start_time = true;
    item.start = at;
    item.interpolation = interpolation;
    return item;
  }

 private:
  ManualClock clock_{Origin()};
  std::shared_ptr<ReferenceRecorder> recorder_;  // declared before the daemon: it outlives the driver
  ObservedDriver* observed_;                     // owned by daemon_
  RobotDaemon daemon_;
  DaemonOutput out_;
  RobotState state_;
};

struct SineStream {
  int joint = 0;  ///< the model's joint index (one dof)
  Interpolation interpolation = Interpolation::kQuintic;
  double frame_hz = 100;   ///< the client's frame rate
  double amplitude = 0.5;  ///< rad
  double sine_hz = 0.5;
  Duration delay = std::chrono::milliseconds(300);  ///< each frame's start time: its sending time + delay
  double seconds = 5;                               ///< the client streams this long
  double settle = 1;  ///< the error is measured from the first start time + settle
  // ... to the time the client sends its last frame: a trajectory comes to
  // rest at its last known waypoint, which a stream that ends does not follow.
};

struct SineResult {
  double max_error = 0, rms_error = 0;  ///< measured position against the continuous sine (rad)
  double max_ref_error = 0;             ///< the server's reference against it (NAN: none handed over)
  int samples = 0, succeeded = 0, modified = 0, other = 0;
  std::string last_note;                     ///< the message of the last answer that was not SUCCESS
  std::vector<double> time, sine, measured;  ///< every control period, from the first frame (s, rad)
};

/// Streams `s` to a fresh daemon around `driver`; the error is sampled every
/// control period from the first start time + settle to the last frame's sending.
inline SineResult RunSineStream(std::unique_ptr<Driver> driver, const SineStream& s) {
  ManualDaemon d(std::move(driver));
  const TimePoint t0 = ManualDaemon::Origin();
  const int dof = d.model().dof_offset(s.joint);
  const auto sine = [&](TimePoint t) {
    return s.amplitude * std::sin(2 * std::numbers::pi * s.sine_hz * ToSeconds(t - t0));
  };
  const Duration frame = FromSeconds(1.0 / s.frame_hz);
  const TimePoint measure_from = t0 + s.delay + FromSeconds(s.settle);
  const TimePoint end = t0 + FromSeconds(s.seconds) + s.delay;
  SineResult r;
  r.max_ref_error = NAN;
  double sum2 = 0;
  CommandId id = 0;
  TimePoint next_frame = t0;
  for (TimePoint t = t0; t <= end; t += d.period()) {
    for (; next_frame <= t && next_frame <= t0 + FromSeconds(s.seconds); next_frame += frame) {
      const TimePoint at = next_frame + s.delay;
      d.daemon().Submit(ManualDaemon::Waypoint(++id, s.joint, at, sine(at), s.interpolation));
    }
    d.RunTo(t);
    const double q = d.state().position[dof];
    r.time.push_back(ToSeconds(t - t0));
    r.sine.push_back(sine(t));
    r.measured.push_back(q);
    if (t < measure_from || t > t0 + FromSeconds(s.seconds)) continue;
    const double e = std::abs(q - sine(t));
    r.max_error = std::max(r.max_error, e);
    sum2 += e * e;
    ++r.samples;
    if (d.driver().ref_time(dof) == t) {
      const double er = std::abs(d.driver().ref_position(dof) - sine(t));
      r.max_ref_error = std::isnan(r.max_ref_error) ? er : std::max(r.max_ref_error, er);
    }
  }
  r.rms_error = r.samples > 0 ? std::sqrt(sum2 / r.samples) : NAN;
  r.succeeded = d.succeeded;
  r.modified = d.modified;
  r.other = d.other;
  r.last_note = d.last_note;
  return r;
}

}  // namespace robotalk::testing

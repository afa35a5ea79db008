// RobotTracker: robotalk-web's side of the LCM bus. It listens to
// ROBOTALK/ANNOUNCE; for every robot announced it connects a RobotClient
// (which loads the configuration with a CONFIG query and synchronises the
// clock) and, while a page is open (SetWatching), asks for the state stream
// at the page's rate (STATE_STREAM query). It keeps only the newest sample of each robot: a 1 kHz stream is
// decimated by the web loop polling it at 30 Hz. A robot no announce names
// for `robot_timeout_s` is marked gone and its client dropped; it is
// connected again when it comes back (a new server id or configuration hash
// also reconnects).
//
// It sends queries and heartbeats, and a panic package on Panic(); never a
// command.
//
// Which robots it tracks and when it connects them (at most 256 names, 32
// connects at once, back-off, forgetting) is robotalk::ConnectScheduler's
// (robotalk/connect_scheduler.h), shared with robotalk-ros2.
//
// Thread safety: Poll() must be called from one thread at a time (it owns the
// kinematics buffers); Panic() from any thread. Internally: one LCM thread for
// announces, the scheduler's thread per connect in progress, one worker
// thread for (blocking) state stream requests, each client's own ReadDaemon
// delivering samples into a single-slot buffer.
// Errors: the constructor throws robotalk::Error when LCM cannot be opened.
// Connection failures are reported in the robot's status, not thrown.
#pragma once

#include "robotalk/robot_model.h"
#include "web_options.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace robotalk::web {

/// What changed since the last Poll().
struct TrackerFrame {
  /// {"type":"robots","robots":[{name, status, message, driver, panic, num_clients,
  /// generation, urdf}]}, status one of "connecting", "live", "gone", "error".
  nlohmann::json robots;
  /// Per robot with a model: (name, generation, the {"type":"model"} message).
  struct Model {
    std::string robot;
    std::uint64_t generation = 0;
    std::shared_ptr<const std::string> message;
    std::shared_ptr<const RobotModel> model;  ///< the model the message describes
  };
  std::vector<Model> models;
  /// {"type":"state"} messages (StatePoser::Pose), one per robot with a sample
  /// newer than the last Poll().
  std::vector<std::string> states;
  /// The same states as objects (the Foxglove endpoint's input).
  std::vector<nlohmann::json> poses;
  /// Samples received from LCM since the last Poll(), over every robot.
  std::uint64_t samples_received = 0;
};

/// The robots `frame` has a model of: every robot the tracker has a model of
/// (it lists each in every frame), so one missing was forgotten. The web
/// loop's caches of robots (page models, Foxglove channels) keep only these.
std::set<std::string> ModelledRobots(const TrackerFrame& frame);

class RobotTracker {
 public:
  explicit RobotTracker(const WebOptions& options);
  ~RobotTracker();
  RobotTracker(const RobotTracker&) = delete;
  RobotTracker& operator=(const RobotTracker&) = delete;

  /// Housekeeping (gone robots, reconnects) and what changed. REQUIRES: one
  /// caller thread at a time.
  TrackerFrame Poll();

  /// Whether any page is open. The state streams are asked for while one is
  /// and cancelled when none is (heartbeats keep the sessions). Any thread.
  void SetWatching(bool watching);

  /// Called (on a client's ReadDaemon thread, after the sample is stored)
  /// for every state sample received, so the web loop can send it at once
  /// instead of at its next tick. Set it before the first SetWatching(true);
  /// it must be quick and must not call back into the tracker.
  void SetOnSample(std::function<void()> on_sample);

  /// Sends a panic package to `robot` on a thread of its own and calls `done`
  /// there with an empty string on success or the reason it failed (not
  /// connected, no acknowledgement). A robot has at most one panic in flight,
  /// on one thread: requests meanwhile are answered together by the next
  /// panic, sent when that one is answered (at most 65,536 wait; later ones are
  /// answered at once saying so). A robot that is not connected is answered
  /// at once, on the caller's thread.
  void Panic(const std::string& robot, std::function<void(const std::string& error)> done);

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace robotalk::web

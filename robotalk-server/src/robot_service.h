// One served robot: its driver, its client sessions, and its RobotDaemon.
//
// Two threads use a RobotService:
// - the ServerDaemon (the transport thread) calls HandlePackage(),
//   TakeReplies(), ExpireSessions() and Info();
// - the RobotDaemon (started by Start()) runs RunOnce() at each due start time
//   and each driver period, with absolute deadlines. It is the real-time path:
//   it never holds mutex_ while calling the driver, and its buffers are
//   preallocated (replies carrying query data still allocate their values).
// Tests may leave the thread unstarted and call RunOnce() themselves with a
// ManualClock.
#pragma once

#include "robotalk/clock.h"
#include "robotalk/driver.h"
#include "robotalk/kinematics.h"
#include "robotalk_msgs/package_t.hpp"
#include "robotalk_msgs/reply_package_t.hpp"
#include "robotalk_msgs/robot_info_t.hpp"
#include "robotalk_msgs/robot_state_t.hpp"
#include "session.h"

#include <atomic>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

namespace robotalk {

struct RobotServiceOptions {
  /// A session that sends nothing for this long expires (watchdog).
  Duration session_timeout = std::chrono::seconds(2);
  /// Most commands one client may have queued.
  size_t max_queue = 10000;
  /// Start times further ahead than this are refused.
  Duration max_future = std::chrono::hours(1);
  /// When playback mode has seen enough frames to estimate its delay.
  PlaybackEstimatorOptions playback;
  /// Print one line per executed command to stderr (a diagnostic audit log;
  /// it does I/O on the RobotDaemon, so leave it off on a real-time system).
  bool log_executions = false;
};

/// What the ServerDaemon sends back at once for a received package.
struct ImmediateAnswer {
  robotalk_msgs::reply_package_t package{};  ///< ack + immediate replies; send_us filled by the sender
  bool send = true;                          ///< false for packages that cannot be answered (no client id)
  bool publish_config = false;               ///< a CONFIG query asked for the configuration message
};

/// A client session the watchdog removed.
struct ExpiredSession {
  std::int64_t client_id = 0;
  size_t dropped_commands = 0;  ///< queued commands that will never run
  bool moved_robot = false;     ///< it had set the robot moving (a STOP follows if still moving)
};

/// Replies for one client, ready to send.
struct OutgoingReplies {
  std::int64_t client_id = 0;
  std::vector<Reply> replies;
};

class RobotService {
 public:
  RobotService(std::string name, std::string driver_name, std::unique_ptr<Driver> driver, const Clock& clock,
               RobotServiceOptions options = {});
  ~RobotService();
  RobotService(const RobotService&) = delete;
  RobotService& operator=(const RobotService&) = delete;

  const std::string& name() const { return name_; }
  const RobotModel& model() const { return driver_->model(); }
  /// The encoded robot_config_t (computed once).
  const std::vector<std::uint8_t>& encoded_config() const { return encoded_config_; }
  std::uint64_t config_hash() const { return config_hash_; }

  /// Starts / stops the RobotDaemon thread. Stop() runs one last iteration
  /// after joining, so a STOP queued by StopRobot() just before still executes.
  void Start();
  void Stop();

  // --- ServerDaemon side ---------------------------------------------------
  /// Handles one decoded package received at `received`.
  ImmediateAnswer HandlePackage(const robotalk_msgs::package_t& package, TimePoint received);
  /// Answers ERROR to every item of a package that failed CheckPackageHeader.
  ImmediateAnswer RefusePackage(const robotalk_msgs::package_t& package, TimePoint received,
                                const std::string& reason);
  /// Moves every reply waiting in the return queues into `out`.
  void TakeReplies(std::vector<OutgoingReplies>& out);
  /// Moves the broadcast state samples taken since the last call into `out`.
  void TakeStates(std::vector<robotalk_msgs::robot_state_t>& out);
  /// The broadcast period now (shortest asked for), or 0 when nobody asks.
  Duration stream_period() const;
  /// Expires silent sessions. If one had set the robot moving and the robot
  /// is still moving when the RobotDaemon looks, it is stopped.
  std::vector<ExpiredSession> ExpireSessions(TimePoint now);
  /// Queues a STOP from the server itself (watchdog, shutdown).
  void StopRobot(const std::string& reason);
  robotalk_msgs::robot_info_t Info() const;
  bool in_panic() const { return panic_.load(); }
  /// Called (from the RobotDaemon) whenever replies are waiting.
  void set_replies_ready_callback(std::function<void()> callback) { replies_ready_ = std::move(callback); }

  // --- RobotDaemon side ----------------------------------------------------
  /// One RobotDaemon iteration at `now`: panic halt/resume, every due item in
  /// start-time order over all clients, and the driver's Update when its
  /// period is due. Returns when it next has work (the next deadline).
  TimePoint RunOnce(TimePoint now);

 private:
  struct Owner {  // who a driver command belongs to
    std::int64_t client_id;
    CommandId client_command_id;
    TimePoint started;  // when the driver took it
    Duration lateness;  // how late after its start time it was taken
  };
  struct Produced {  // a reply on its way to a return queue
    std::int64_t client_id;
    Reply reply;
  };

  Session& SessionFor(std::int64_t client_id, TimePoint now);  // REQUIRES: mutex_ held
  // Checks a command; returns it ready to queue, or answers it in `immediate`.
  std::optional<QueuedItem> PrepareCommand(Session& s, const robotalk_msgs::command_t& wire, TimePoint now,
                                           std::vector<Reply>& immediate,
                                           bool playback);  // REQUIRES: mutex_ held
  void EnqueueCommand(Session& s, const robotalk_msgs::command_t& wire, TimePoint now,
                      std::vector<Reply>& immediate);  // REQUIRES: mutex_ held
  void EnqueuePlayback(Session& s, const robotalk_msgs::package_t& package, TimePoint now,
                       std::vector<Reply>& immediate);  // REQUIRES: mutex_ held
  void UpdateStream(TimePoint now);                     // REQUIRES: mutex_ held
  void SampleState(TimePoint now, Duration period);     // RobotDaemon, no lock
  void EnqueueQuery(Session& s, const robotalk_msgs::query_t& wire, TimePoint now,
                    std::vector<Reply>& immediate,
                    bool& publish_config);                 // REQUIRES: mutex_ held
  void PanicNow(std::int64_t client_id, TimePoint now);    // REQUIRES: mutex_ held
  void Deliver(std::int64_t client_id, Reply reply);       // REQUIRES: mutex_ held
  void Execute(const QueuedItem& item, TimePoint now);     // RobotDaemon, no lock
  void AnswerQuery(const QueuedItem& item, Reply& reply);  // RobotDaemon, no lock
  void DaemonLoop();
  void QueueStop(const std::string& reason, bool only_if_moving);

  const std::string name_;
  const std::string driver_name_;
  std::unique_ptr<Driver> driver_;
  const Clock& clock_;
  const RobotServiceOptions options_;
  std::vector<std::uint8_t> encoded_config_;
  std::uint64_t config_hash_ = 0;
  std::function<void()> replies_ready_;

  // Shared between the two threads.
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::map<std::int64_t, Session> sessions_;  // GUARDED_BY(mutex_)
  std::vector<QueuedItem> server_queue_;      // GUARDED_BY(mutex_): watchdog / shutdown STOPs
  std::uint64_t arrivals_ = 0;                // GUARDED_BY(mutex_)
  bool halt_requested_ = false;               // GUARDED_BY(mutex_)
  bool resume_requested_ = false;             // GUARDED_BY(mutex_)
  bool wake_flag_ = false;                    // GUARDED_BY(mutex_)
  bool running_ = false;                      // GUARDED_BY(mutex_)
  // Broadcast: one stream at the shortest period any client asked for.
  std::map<std::int64_t, Duration> stream_requests_;        // GUARDED_BY(mutex_)
  Duration stream_period_{0};                               // GUARDED_BY(mutex_); 0 = off
  TimePoint next_sample_{};                                 // GUARDED_BY(mutex_)
  std::uint64_t stream_generation_ = 0;                     // GUARDED_BY(mutex_)
  std::vector<robotalk_msgs::robot_state_t> state_outbox_;  // GUARDED_BY(mutex_)
  std::atomic<bool> panic_{false};

  // RobotDaemon only (preallocated).
  std::thread daemon_;
  std::vector<QueuedItem> due_;
  std::vector<Completion> completions_;
  std::vector<Produced> produced_;
  std::unordered_map<CommandId, Owner> in_progress_;  // driver command id -> owner
  CommandId next_driver_id_ = 1;
  RobotState state_;
  Kinematics kinematics_;
  TimePoint next_update_ = TimePoint::min();
  std::int64_t samples_ = 0;
  std::vector<robotalk_msgs::robot_state_t> sampled_;
};

}  // namespace robotalk

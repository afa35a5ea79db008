// FakeServer: a tiny in-process RoboTalk server for client tests, on a shared
// Transport (a MemoryTransport in the tests; an LcmTransport in
// robotalk_fake_server). It follows docs/protocol.md closely enough to
// exercise the client: acks every package, answers queries at once, executes a
// command once per (client, sequence) and re-sends ack + final replies for a
// repeated sequence, schedules commands with a future start time, handles panic.
// Faults it can inject: silence, lost and duplicated reply packages, replies of
// a batch in reverse order, the first delayed reply lost.
//
// Its handler runs on whichever thread calls HandleFor() (the client's
// ReadDaemon); delayed replies leave from its own worker thread.
//
// Thread safety: every method may be called from any thread.
#pragma once

#include "robotalk/robot_model.h"
#include "robotalk_msgs/package_t.hpp"
#include "robotalk_msgs/reply_package_t.hpp"

#include "robotalk/transport.h"

#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <thread>
#include <vector>

namespace robotalk::testing {

struct FakeServerOptions {
  std::chrono::seconds clock_offset{1000};  ///< server clock = steady clock + this
  bool mute = false;                        ///< receive but answer nothing
  double reply_drop_probability = 0.0;
  bool duplicate_replies = false;
  bool reverse_batches = false;  ///< a batch's replies, one package each, last first
  bool drop_first_delayed_reply = false;
  std::uint64_t seed = 99;
};

class FakeServer {
 public:
  FakeServer(Transport& transport, RobotModel model, FakeServerOptions options = {});
  ~FakeServer();
  FakeServer(const FakeServer&) = delete;
  FakeServer& operator=(const FakeServer&) = delete;

  void SetMute(bool mute);
  /// As if the server process restarted: a new instance id, no sessions, no
  /// memory of packages; packages of old sessions are answered SESSION_UNKNOWN.
  void Restart();
  int hellos() const;
  /// Publishes one announce_t for this robot.
  void Announce(std::int64_t server_id);

  int executions(std::int64_t command_id) const;
  int total_executions() const;
  int packages_received() const;
  int repeated_packages() const;
  int heartbeats() const;
  bool panic() const;
  std::int64_t ServerNowUs() const;

 private:
  void OnRequest(std::span<const std::uint8_t> bytes);
  void OnHello(std::span<const std::uint8_t> bytes);
  void SendLocked(robotalk_msgs::reply_package_t p);  // REQUIRES: mu_
  void Worker();

  struct Delayed {
    std::int64_t due_us;
    std::int64_t client_id;
    robotalk_msgs::reply_t reply;
  };

  Transport& transport_;
  RobotModel model_;
  FakeServerOptions options_;
  std::unique_ptr<Subscription> sub_;
  std::unique_ptr<Subscription> hello_sub_;
  std::int64_t server_id_ = 1;                     // GUARDED_BY(mu_)
  std::map<std::int64_t, std::int64_t> sessions_;  // GUARDED_BY(mu_): client -> session
  std::int64_t next_session_ = 1000;               // GUARDED_BY(mu_)
  int hellos_ = 0;                                 // GUARDED_BY(mu_)
  mutable std::mutex mu_;
  std::mt19937_64 rng_;
  std::map<std::pair<std::int64_t, std::int64_t>, std::vector<std::int64_t>> seen_;  // (client, seq) -> ids
  std::map<std::int64_t, robotalk_msgs::reply_t> finals_;                            // id -> final reply
  std::map<std::int64_t, int> executions_;
  std::vector<Delayed> delayed_;
  bool panic_ = false;
  bool dropped_first_delayed_ = false;
  int packages_ = 0, repeated_ = 0, heartbeats_ = 0;
  std::atomic<bool> stop_{false};
  std::thread worker_;
};

}  // namespace robotalk::testing

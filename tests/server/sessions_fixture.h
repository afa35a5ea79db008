// The session layer of one robot and its RobotDaemon on a fake driver and a
// manual clock, without threads or a transport, for RobotSessions tests
// (robot_sessions_test.cpp, watchdog_test.cpp, session_memory_test.cpp).
#pragma once

#include "fake_driver.h"
#include "robot_sessions.h"
#include "robotalk/config_message.h"
#include "robotalk/request.h"
#include "state_encoding.h"
#include "support/test_clients.h"

#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace robotalk::testing {

inline Command Cmd(CommandId id, CommandType type, std::vector<double> values = {}, std::string target = "",
                   StartTime start = StartTime::Now()) {
  return Command{id, type, start, std::move(target), std::move(values)};
}

inline Request Package(std::int64_t client, std::int64_t seq, const std::vector<Command>& commands,
                       bool panic = false) {
  Request r{.client_id = client, .sequence = seq, .panic = panic};
  r.commands = commands;
  return r;
}

inline Request Queries(std::int64_t client, std::int64_t seq, const std::vector<Query>& queries) {
  Request r{.client_id = client, .sequence = seq};
  r.queries = queries;
  return r;
}

// A playback frame's start_time is After(its offset from the sequence start).
inline Request Playback(std::int64_t client, std::int64_t seq, std::int64_t playback_id, int frames,
                        Duration duration, const std::vector<Command>& commands) {
  Request r = Package(client, seq, commands);
  r.mode = RequestMode::kPlayback;
  r.playback = {playback_id, frames, duration};
  return r;
}

// The ServerDaemon's session layer of one robot and its RobotDaemon, on a
// manual clock, without threads or a transport.
class RobotSessionsTest : public ::testing::Test {
 protected:
  explicit RobotSessionsTest(BaseType base = BaseType::kDifferential, SessionOptions options = {}) {
    auto driver = std::make_unique<FakeDriver>(PanRobot(base));
    fake_ = driver.get();
    daemon_ = std::make_unique<RobotDaemon>("bot", "fake", std::move(driver), clock_);
    sessions_ = std::make_unique<RobotSessions>(*daemon_, ConfigHash(daemon_->model()), options);
    daemon_->Preallocate(output_);
  }

  // Immediate replies of a package, by id.
  std::map<CommandId, Reply> Handle(const Request& p) {
    std::map<CommandId, Reply> out;
    last_ = sessions_->Handle(p, clock_.Now());
    for (const auto& r : last_.batch.replies) out[r.id] = r;
    return out;
  }
  // Runs the RobotDaemon once at the current time and files what it produced.
  void Run() {
    daemon_->RunOnce(clock_.Now());
    Collect();
  }
  void Collect() {
    daemon_->TakeOutput(output_);
    for (std::size_t i = 0; i < output_.num_samples; ++i) {
      states_.push_back(ToStateSample("bot", ConfigHash(daemon_->model()), output_.samples[i]));
    }
    std::vector<ReplyBatch> batches;
    sessions_->File(output_, batches);
    for (auto& b : batches) {
      for (auto& r : b.replies) collected_[b.client_id][r.id] = r;
    }
  }
  std::map<CommandId, Reply> Replies(std::int64_t client) {
    Collect();
    return collected_[client];
  }

  ManualClock clock_;
  FakeDriver* fake_ = nullptr;
  std::unique_ptr<RobotDaemon> daemon_;
  std::unique_ptr<RobotSessions> sessions_;
  DaemonOutput output_;
  ImmediateAnswer last_;
  std::map<std::int64_t, std::map<CommandId, Reply>> collected_;
  std::vector<StateSample> states_;
};

}  // namespace robotalk::testing

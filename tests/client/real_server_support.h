// Helpers for tests that run the client against the real server core
// (robot_client_test.cpp): a clock at an offset from the steady clock, a
// driver wrapper that logs what the server asked of it, filters on wire bytes
// for FaultyTransport faults, and a bounded real-time wait.
#pragma once

#include "client/faulty_transport.h"
#include "robotalk/clock.h"
#include "robotalk/driver.h"
#include "robotalk/protocol_codec.h"

#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <utility>

namespace robotalk::testing {

// The steady clock moved by a fixed offset: the client's clock, 1000 s behind
// the server's, so that the measured clock offset cannot be right by accident.
// (The server itself must run on the steady clock: its RobotDaemon sleeps
// until deadlines on std::chrono::steady_clock.)
class OffsetClock final : public Clock {
 public:
  explicit OffsetClock(Duration offset) : offset_(offset) {}
  TimePoint Now() const override { return steady_.Now() + offset_; }

 private:
  SteadyClock steady_;
  Duration offset_;
};

// What the server asked of the driver, by command type and first value (the
// server gives the driver ids of its own, so tests tell their commands apart
// by value); read by the test thread while the RobotDaemon's thread writes it.
class DriverLog {
 public:
  void Executed(const DriverCommand& c) {
    std::lock_guard lock(mu_);
    ++executed_[{c.type, c.num_values > 0 ? c.values[0] : 0.0}];
  }
  void Halted(bool halted) {
    std::lock_guard lock(mu_);
    halted_ = halted;
  }
  int executions(CommandType type, double first_value) const {
    std::lock_guard lock(mu_);
    auto it = executed_.find({type, first_value});
    return it == executed_.end() ? 0 : it->second;
  }
  int total() const {
    std::lock_guard lock(mu_);
    int n = 0;
    for (const auto& [key, count] : executed_) n += count;
    return n;
  }
  bool halted() const {
    std::lock_guard lock(mu_);
    return halted_;
  }

 private:
  mutable std::mutex mu_;
  std::map<std::pair<CommandType, double>, int> executed_;
  bool halted_ = false;
};

// The kinematic driver, logging each Execute, Halt and Resume.
class CountingDriver final : public Driver {
 public:
  CountingDriver(std::unique_ptr<Driver> inner, std::shared_ptr<DriverLog> log)
      : inner_(std::move(inner)), log_(std::move(log)) {}
  const RobotModel& model() const override { return inner_->model(); }
  Duration period() const override { return inner_->period(); }
  DriverResult Execute(const DriverCommand& c, TimePoint now, std::vector<Completion>& done) override {
    log_->Executed(c);
    return inner_->Execute(c, now, done);
  }
  void Update(TimePoint now, std::vector<Completion>& done) override { inner_->Update(now, done); }
  void ReadState(RobotState& s) const override { inner_->ReadState(s); }
  void Stop(TimePoint now, std::vector<Completion>& done) override { inner_->Stop(now, done); }
  void Halt(std::vector<Completion>& done) override {
    log_->Halted(true);
    inner_->Halt(done);
  }
  void Resume() override {
    log_->Halted(false);
    inner_->Resume();
  }

 private:
  std::unique_ptr<Driver> inner_;
  std::shared_ptr<DriverLog> log_;
};

// --- Filters on wire bytes, for FaultyTransport faults ------------------------

inline bool IsHeartbeat(const std::string&, std::span<const std::uint8_t> bytes) {
  try {
    const auto p = DecodePackage(bytes);
    return p.header.payload_size == 0 && !p.header.panic;
  } catch (const std::exception&) {
    return false;
  }
}

inline bool HasPayload(const std::string&, std::span<const std::uint8_t> bytes) {
  try {
    return DecodePackage(bytes).header.payload_size > 0;
  } catch (const std::exception&) {
    return false;
  }
}

inline bool HasReplies(const std::string&, std::span<const std::uint8_t> bytes) {
  try {
    return !DecodeReplyPackage(bytes).replies.empty();
  } catch (const std::exception&) {
    return false;
  }
}

// True for a package whose (client, sequence) was seen before: a retransmission or a duplicate.
inline MessageFilter Repeated() {
  auto seen = std::make_shared<std::set<std::pair<std::int64_t, std::int64_t>>>();
  return [seen](const std::string&, std::span<const std::uint8_t> bytes) {
    try {
      const auto p = DecodePackage(bytes);
      return !seen->insert({p.header.client_id, p.header.sequence}).second;
    } catch (const std::exception&) {
      return false;
    }
  };
}

// Polls `done` every millisecond for at most `bound` of real time (the
// server's and the client's threads run on their own); returns done().
template <typename Done>
bool WaitUntil(Done done, Duration bound = std::chrono::seconds(5)) {
  const auto end = std::chrono::steady_clock::now() + bound;
  while (!done() && std::chrono::steady_clock::now() < end)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  return done();
}

}  // namespace robotalk::testing

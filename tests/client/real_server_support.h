// Helpers for tests that run the client against the real server core
// (robot_client_test.cpp): a log of what the server asked of the driver, filters on wire bytes
// for FaultyTransport faults, and a bounded real-time wait.
#pragma once

#include "client/faulty_transport.h"
#include "robotalk/clock.h"
#include "robotalk/driver.h"
#include "robotalk/request.h"
#include "support/observed_driver.h"

#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <thread>
#include <utility>

namespace robotalk::testing {

// What the server asked of the driver, by command type and first value (the
// server gives the driver ids of its own, so tests tell their commands apart
// by value); read by the test thread while the RobotDaemon's thread writes it.
class DriverLog final : public DriverObserver {
 public:
  void Executed(const DriverCommand& c, TimePoint) override {
    std::lock_guard lock(mu_);
    ++executed_[{c.type, c.num_values > 0 ? c.values[0] : 0.0}];
  }
  void Halted(bool halted) override {
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

// --- Filters on wire bytes, for FaultyTransport faults (the server's decoders) --

inline bool IsHeartbeat(const std::string&, std::span<const std::uint8_t> bytes) {
  try {
    const Request r = DecodeRequest(bytes);
    return r.item_ids().empty() && !r.panic;
  } catch (const std::exception&) {
    return false;
  }
}

inline bool HasPayload(const std::string&, std::span<const std::uint8_t> bytes) {
  try {
    return !DecodeRequest(bytes).item_ids().empty();
  } catch (const std::exception&) {
    return false;
  }
}

inline bool HasReplies(const std::string&, std::span<const std::uint8_t> bytes) {
  try {
    return !DecodeReplyBatch(bytes).replies.empty();
  } catch (const std::exception&) {
    return false;
  }
}

// True for a package whose (client, sequence) was seen before: a retransmission or a duplicate.
inline MessageFilter Repeated() {
  auto seen = std::make_shared<std::set<std::pair<std::int64_t, std::int64_t>>>();
  return [seen](const std::string&, std::span<const std::uint8_t> bytes) {
    try {
      const Request r = DecodeRequest(bytes);
      return !seen->insert({r.client_id, r.sequence}).second;
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

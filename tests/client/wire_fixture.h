// The fixture of the client's wire tests (client_wire_test.cpp,
// trajectories_test.cpp): a RobotClient against the real server core
// (robotalk::Server, kinematic Pioneer) on an in-process MemoryBus, whose
// server end is a FaultyTransport whose incoming `when` predicate records
// each REQUEST package, decoded with the server's own decoder
// (DecodeRequest), and never matches.
#pragma once

#include "client/faulty_transport.h"
#include "client/real_server_support.h"
#include "kinematic_driver.h"
#include "robotalk/channels.h"
#include "robotalk/client_errors.h"
#include "robotalk/memory_transport.h"
#include "robotalk/request.h"
#include "robotalk/robot_client.h"
#include "robotalk/server.h"

#include <gtest/gtest.h>

#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

namespace robotalk::testing {

using std::chrono::milliseconds;
using std::chrono::seconds;

inline const std::string kRobot = "pioneer";

class RobotClientWireTest : public ::testing::Test {
 protected:
  RobotClientWireTest() {
    RegisterKinematicDriver(registry_);
    server_net_.Add({.channel_regex = RequestChannel(kRobot),
                     .direction = Direction::kIncoming,
                     .when = [this](const std::string& channel, std::span<const std::uint8_t> bytes) {
                       std::lock_guard lock(mu_);
                       sent_.push_back(DecodeRequest(bytes));  // throws: the test fails loudly
                       heard_.push_back({channel, {bytes.begin(), bytes.end()}});
                       return false;
                     }});
    server_net_.Add({.channel_regex = "ROBOTALK/" + kRobot + "/REPLY/.*",
                     .direction = Direction::kOutgoing,
                     .when = [this](const std::string& channel, std::span<const std::uint8_t> bytes) {
                       std::lock_guard lock(mu_);
                       heard_.push_back({channel, {bytes.begin(), bytes.end()}});
                       return false;
                     }});
    ServerOptions o;
    o.precise_timing = false;
    const RobotSpec spec{
        kRobot, "kinematic", std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf", {}};
    server_ = std::make_unique<Server>(server_net_, o, std::vector<RobotSpec>{spec}, registry_, clock_);
    server_->Start();
    ClientOptions c;
    c.transport = &client_end_;
    c.timeout = seconds(5);
    c.connect_timeout = seconds(5);
    client_ = std::make_unique<RobotClient>(c);
    client_->Connect(kRobot);
  }

  // The REQUEST packages the server received since the last call, each once.
  std::vector<Request> TakeSent() {
    std::lock_guard lock(mu_);
    std::vector<Request> out;
    std::set<std::int64_t> seen;
    for (Request& r : sent_) {
      if (seen.insert(r.sequence).second) out.push_back(std::move(r));
    }
    sent_.clear();
    return out;
  }
  // Every REQUEST and REPLY message so far, in order, as a logger heard it.
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> Heard() {
    std::lock_guard lock(mu_);
    return heard_;
  }
  static std::vector<TimedCommand> Frames(int n) {
    std::vector<TimedCommand> frames;
    for (int i = 0; i < n; ++i) {
      frames.push_back({milliseconds(20 * i), Command{.type = CommandType::kSetSpeed, .values = {0.0, 0.0}}});
    }
    return frames;
  }

  std::shared_ptr<MemoryBus> bus_ = std::make_shared<MemoryBus>();
  MemoryTransport server_end_{bus_};
  MemoryTransport client_end_{bus_};
  std::mutex mu_;
  std::vector<Request> sent_;                                             // GUARDED_BY(mu_)
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> heard_;  // GUARDED_BY(mu_)
  FaultyTransport server_net_{server_end_, {.seed = 3}};
  SteadyClock clock_;
  DriverRegistry registry_;
  std::unique_ptr<Server> server_;
  std::unique_ptr<RobotClient> client_;  // first to go: its heartbeats stop before the server
};

// Every package the server decoded; the ones carrying commands, by mode.
inline void ExpectCommandPackagesIn(const std::vector<Request>& sent, RequestMode mode,
                                    std::size_t commands) {
  std::size_t seen = 0;
  for (const Request& r : sent) {
    EXPECT_EQ(r.header_error, "") << "package " << r.sequence;
    EXPECT_TRUE(r.malformed.empty()) << "package " << r.sequence;
    if (r.commands.empty()) continue;
    EXPECT_EQ(static_cast<int>(r.mode), static_cast<int>(mode)) << "package " << r.sequence;
    seen += r.commands.size();
  }
  EXPECT_EQ(seen, commands);
}

}  // namespace robotalk::testing

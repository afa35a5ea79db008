// What the C++ client puts on the wire, read back with the server's own
// decoder (DecodeRequest, request.h): every package the client sends --
// single calls, sequences in each mode, heartbeats, panics -- is one the
// server's codec reads without a header error, labelled with the package
// mode docs/protocol.md documents (issue 20 item 1: delay sequences, and
// `robotalk send --file`'s delay batches, went out as MODE_DIRECT, so
// `robotalk-logplay export` called every delay session "direct"). And what the client reads: a reply package
// with one reply it cannot decode still delivers the others.
//
// Against the real server core (robotalk::Server, kinematic driver) on an
// in-process MemoryBus; the server's end is a FaultyTransport whose incoming
// `when` predicate records each REQUEST package and never matches.
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

#include <future>
#include <mutex>
#include <set>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using namespace robotalk::testing;  // NOLINT: FaultyTransport and the helpers of real_server_support.h

const std::string kRobot = "pioneer";

class RobotClientWireTest : public ::testing::Test {
 protected:
  RobotClientWireTest() {
    RegisterKinematicDriver(registry_);
    server_net_.Add({.channel_regex = RequestChannel(kRobot),
                     .direction = Direction::kIncoming,
                     .when = [this](const std::string&, std::span<const std::uint8_t> bytes) {
                       std::lock_guard lock(mu_);
                       sent_.push_back(DecodeRequest(bytes));  // throws: the test fails loudly
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
  std::vector<Request> sent_;  // GUARDED_BY(mu_)
  FaultyTransport server_net_{server_end_, {.seed = 3}};
  SteadyClock clock_;
  DriverRegistry registry_;
  std::unique_ptr<Server> server_;
  std::unique_ptr<RobotClient> client_;  // first to go: its heartbeats stop before the server
};

// Every package the server decoded; the ones carrying commands, by mode.
void ExpectCommandPackagesIn(const std::vector<Request>& sent, RequestMode mode, std::size_t commands) {
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

TEST_F(RobotClientWireTest, ADelaySequenceTravelsInMODE_DELAYPackagesWithAbsoluteStartTimes) {
  TakeSent();
  const SequenceResult result =
      client_->RunSequence(Frames(4), {.mode = CommandMode::kDelay, .delay = milliseconds(300)});
  for (const Reply& r : result.replies) EXPECT_EQ(r.signal, Signal::kSuccess) << r.message;
  const std::vector<Request> sent = TakeSent();
  ExpectCommandPackagesIn(sent, RequestMode::kDelay, 4);
  for (const Request& r : sent) {
    for (const Command& c : r.commands) EXPECT_TRUE(c.start_time.is_at()) << ToString(c.start_time);
  }
}

// `robotalk send --file` sends its delay sequence piece by piece through SendBatch.
TEST_F(RobotClientWireTest, ABatchSentInDelayModeTravelsAsMODE_DELAYAndAPlaybackBatchIsRefused) {
  TakeSent();
  const TimePoint start = client_->ServerNow() + milliseconds(100);
  auto pending =
      client_->SendBatch({Command{.type = CommandType::kStop, .start_time = start}}, CommandMode::kDelay);
  ASSERT_EQ(pending.size(), 1u);
  EXPECT_EQ(pending[0].Wait(seconds(5)).signal, Signal::kSuccess);
  ExpectCommandPackagesIn(TakeSent(), RequestMode::kDelay, 1);
  EXPECT_THROW(client_->SendBatch({Command{.type = CommandType::kStop}}, CommandMode::kPlayback),
               ClientError);
}

TEST_F(RobotClientWireTest, SingleCallsAndDirectSequencesTravelInMODE_DIRECT) {
  TakeSent();
  EXPECT_EQ(client_->Stop().signal, Signal::kSuccess);
  const SequenceResult result = client_->RunSequence(Frames(2), {.mode = CommandMode::kDirect});
  for (const Reply& r : result.replies) EXPECT_EQ(r.signal, Signal::kSuccess) << r.message;
  ExpectCommandPackagesIn(TakeSent(), RequestMode::kDirect, 3);
}

TEST_F(RobotClientWireTest, APlaybackSequenceDeclaresItselfInMODE_PLAYBACKPackagesOfOffsets) {
  TakeSent();
  const SequenceResult result = client_->RunSequence(Frames(6), {.mode = CommandMode::kPlayback});
  for (const Reply& r : result.replies) EXPECT_EQ(r.signal, Signal::kSuccess) << r.message;
  const std::vector<Request> sent = TakeSent();
  ExpectCommandPackagesIn(sent, RequestMode::kPlayback, 6);
  for (const Request& r : sent) {
    if (r.commands.empty()) continue;
    EXPECT_EQ(r.playback.frames, 6);
    EXPECT_EQ(r.playback.duration, milliseconds(100));
    for (const Command& c : r.commands) EXPECT_TRUE(c.start_time.is_after()) << ToString(c.start_time);
  }
}

TEST_F(RobotClientWireTest, APanicAndQueriesAreEmptyOrQueryPackagesTheServerReadsWithoutError) {
  TakeSent();
  client_->Panic();
  EXPECT_EQ(client_->ResetPanic().signal, Signal::kSuccess);
  EXPECT_EQ(client_->BasePose().signal, Signal::kSuccess);
  const std::vector<Request> sent = TakeSent();
  ExpectCommandPackagesIn(sent, RequestMode::kDirect, 1);  // the PANIC_RESET
  std::size_t panics = 0, queries = 0;
  for (const Request& r : sent) {
    if (r.panic) {
      ++panics;
      EXPECT_TRUE(r.item_ids().empty());
    }
    queries += r.queries.size();
  }
  EXPECT_EQ(panics, 1u);
  EXPECT_EQ(queries, 1u);
}

// The server is gone; the test answers by hand with a batch whose second
// reply carries a signal this client does not know.
TEST_F(RobotClientWireTest, AReplyPackageWithAnUndecodableReplyStillDeliversTheOthers) {
  server_.reset();
  auto answer = server_end_.Subscribe(
      RequestChannel(kRobot), [&](const std::string&, std::span<const std::uint8_t> bytes) {
        const Request r = DecodeRequest(bytes);
        ReplyBatch b{.client_id = r.client_id, .session_id = r.session_id, .ack_sequence = r.sequence};
        for (CommandId id : r.item_ids()) {
          b.replies.push_back(Reply{.id = id, .signal = Signal::kSuccess, .values = {1, 2, 3}});
          b.replies.push_back(Reply{.id = id + 1000, .signal = static_cast<Signal>(99)});
        }
        server_end_.Publish(ReplyChannel(kRobot, r.client_id), EncodeReplyBatch(b));
      });
  const std::uint64_t malformed_before = client_->stats().malformed_packages;
  auto done = std::async(std::launch::async, [&] { return client_->BasePose(); });
  while (done.wait_for(milliseconds(1)) != std::future_status::ready) server_end_.HandleFor(milliseconds(5));
  const Reply r = done.get();
  EXPECT_EQ(r.signal, Signal::kSuccess);
  EXPECT_EQ(r.values, (std::vector<double>{1, 2, 3}));
  EXPECT_GT(client_->stats().malformed_packages, malformed_before);
}

}  // namespace
}  // namespace robotalk

// What measures the link comes from when a package reached the socket, not
// from when the ServerDaemon got round to handling it (issue 23 item 3): a
// loaded server that handles each package 20 ms after the one before it must
// not put those 20 ms into link health's transits (its jitter) or into the
// receive time it answers for the client's clock (t2, which the round trip
// and the offset leave out). Playback's one-way delays keep them: a frame can
// play only once it was handled, so this server's own lag is part of what
// the start must cover (the paper's Fig. 11 congestion is a server pausing
// after each package; with the socket's stamp the adaptive start's gate missed
// it and ServerClientTest.PlaybackKeepsTheInterFrameTimingUnderCongestion
// played its frames 0.4 s late).
//
// The ServerDaemon on the in-memory transport (whose receive stamp is the
// publish time), with the client's packages stamped on the same steady clock:
// every true one-way delay is well under a millisecond.
#include "fake_driver.h"
#include "robotalk/channels.h"
#include "robotalk/forwarding_transport.h"
#include "robotalk/memory_transport.h"
#include "robotalk/request.h"
#include "server_daemon.h"
#include "session_test_util.h"
#include "sessions_fixture.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <map>
#include <thread>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using namespace robotalk::testing;  // NOLINT: the sessions fixture's helpers

// Every handler runs `lag` after the one before it could have (a ServerDaemon
// whose thread is starved): a burst of packages queues, each handled later
// than it arrived. ReceiveTime() still says when each came.
class LateHandlerTransport final : public ForwardingTransport {
 public:
  LateHandlerTransport(Transport& inner, Duration lag) : ForwardingTransport(inner), lag_(lag) {}
  std::unique_ptr<Subscription> Subscribe(const std::string& channel_regex, Handler handler) override {
    return inner().Subscribe(channel_regex,
                             [this, handler = std::move(handler)](const std::string& channel,
                                                                  std::span<const std::uint8_t> bytes) {
                               std::this_thread::sleep_for(lag_);
                               handler(channel, bytes);
                             });
  }

 private:
  Duration lag_;
};

class ServerReceiveStampTest : public ::testing::Test {
 protected:
  ServerReceiveStampTest() : server_end_(bus_), late_(server_end_, milliseconds(20)), client_(bus_) {
    robot_ = std::make_unique<RobotDaemon>("arm", "fake", std::make_unique<FakeDriver>(PanRobot()), clock_);
    server_ = std::make_unique<ServerDaemon>(late_, clock_, ServerDaemonOptions{.server_id = 7});
    server_->AddRobot(*robot_, SessionOptions{});
    sub_ = client_.Subscribe(ReplyChannel("arm", kAlice),
                             [this](const std::string&, std::span<const std::uint8_t> b) {
                               ReplyBatch batch = DecodeReplyBatch(b);
                               receive_[batch.ack_sequence] = batch.server_receive;
                               for (Reply& r : batch.replies) replies_[r.id] = r;
                             });
    session_ = SayHello(client_, "arm", kAlice, [this] { Step(); }).session_id;
  }
  void Step() {
    server_->RunOnce(Duration(0));
    robot_->RunOnce(clock_.Now());
    server_->RunOnce(Duration(0));
    client_.HandleFor(Duration(0));
  }
  // Published now, stamped with the (shared) clock's now as its send time.
  TimePoint Send(Request r) {
    r.session_id = session_;
    r.send_time = clock_.Now();
    client_.Publish(RequestChannel("arm"), EncodeRequest(r));
    return r.send_time;
  }
  const Session& session() const { return *server_->sessions().Find(0, kAlice); }

  SteadyClock clock_;
  std::shared_ptr<MemoryBus> bus_ = std::make_shared<MemoryBus>();
  MemoryTransport server_end_;
  LateHandlerTransport late_;
  MemoryTransport client_;
  std::unique_ptr<RobotDaemon> robot_;
  std::unique_ptr<ServerDaemon> server_;
  std::unique_ptr<Subscription> sub_;
  std::int64_t session_ = 0;
  std::map<std::int64_t, TimePoint> receive_;  // ack sequence -> server_receive
  std::map<CommandId, Reply> replies_;
};

TEST_F(ServerReceiveStampTest, TheClockSampleAndLinkHealthLeaveOutTheServersHandlingLagPlaybackKeepsIt) {
  // A burst of four clock rounds: handled 20, 40, 60 and 80 ms after they came.
  std::map<std::int64_t, TimePoint> sent;
  for (std::int64_t seq = 1; seq <= 4; ++seq)
    sent[seq] = Send(Queries(kAlice, seq, {Query{.id = 100 + seq, .type = QueryType::kClock}}));
  Step();
  ASSERT_EQ(receive_.size(), 4u) << "every round acknowledged";
  // Before: the handling time, 20-80 ms after each was sent.
  for (const auto& [seq, at] : receive_)
    EXPECT_LT(at - sent.at(seq), milliseconds(10)) << "package " << seq << "'s server_receive (t2)";
  // Before: transits 20 ms apart, a jitter of 3.6 ms.
  EXPECT_LT(session().link.Figures().jitter, milliseconds(1)) << "link health's jitter";
  // Playback's delays: from when each could act (at least its 20 ms wait).
  const std::vector<Duration> delays = session().delays.Recent(clock_.Now());
  ASSERT_EQ(delays.size(), 4u);
  for (Duration d : delays) EXPECT_GE(d, milliseconds(20)) << "a one-way delay in playback's history";
}

}  // namespace
}  // namespace robotalk

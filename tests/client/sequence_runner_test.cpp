// The CLI's sequence runner (robotalk-client/cli/sequence_runner.h) against
// the real server core (robotalk::Server, kinematic driver, 1 ms period) on
// an in-process bus: direct frames wake on their reply (issue 21 item 5),
// delay mode reports each reply in order, and a stop request ends a delay
// sequence at once, naming the frames still queued on the server.
#include "sequence_runner.h"

#include "kinematic_driver.h"
#include "robotalk/memory_transport.h"
#include "robotalk/server.h"

#include <gtest/gtest.h>

#include <ctime>

#include <cstdio>
#include <stop_token>

namespace robotalk::cli {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;

class SequenceRunnerTest : public ::testing::Test {
 protected:
  SequenceRunnerTest() {
    RegisterKinematicDriver(registry_);
    ServerOptions o;
    o.precise_timing = false;  // no spinning or SCHED_FIFO on a shared test machine
    const RobotSpec spec{"pioneer",
                         "kinematic",
                         std::string(ROBOTALK_MODELS_DIR) + "/pioneer2dx_pantilt.urdf",
                         {{"period_ms", "1"}}};
    server_ = std::make_unique<Server>(server_end_, o, std::vector<RobotSpec>{spec}, registry_, clock_);
    server_->Start();
    ClientOptions c;
    c.transport = &client_end_;
    client_ = std::make_unique<RobotClient>(c);
    client_->Connect("pioneer");
  }
  ~SequenceRunnerTest() override {
    client_.reset();
    server_.reset();
  }

  static std::vector<TimedCommand> PanFrames(std::size_t n, Duration step) {
    std::vector<TimedCommand> frames;
    for (std::size_t i = 0; i < n; ++i) {
      frames.push_back(
          {step * static_cast<int>(i), Command{.type = CommandType::kJointSetPoint,
                                               .target = "pan",
                                               .values = {0.001 * static_cast<double>(i % 10)}}});
    }
    return frames;
  }

  // Runs `frames` and requests a stop when the `stop_after`-th reply arrives;
  // counts the replies in `answered`.
  RunReport RunThenStop(std::vector<TimedCommand> frames, const SequenceOptions& options,
                        std::size_t stop_after, std::size_t& answered) {
    std::stop_source stop;
    return RunFrames(
        *client_, std::move(frames), options,
        [&](std::size_t, const Reply&) {
          if (++answered == stop_after) stop.request_stop();
        },
        nullptr, stop.get_token());
  }

  std::shared_ptr<MemoryBus> bus_ = std::make_shared<MemoryBus>();
  MemoryTransport server_end_{bus_};
  MemoryTransport client_end_{bus_};
  SteadyClock clock_;
  DriverRegistry registry_;
  std::unique_ptr<Server> server_;
  std::unique_ptr<RobotClient> client_;
};

// Before the fix each reply was noticed at the next 20 ms polling slice:
// 50 frames due together took >= 1 s. Woken by the reply they take a few
// round trips each; 0.5 s can only be missed by polling.
TEST_F(SequenceRunnerTest, DirectFramesDueTogetherEachLeaveWhenThePreviousReplyArrives) {
  constexpr std::size_t kFrames = 50;
  // A bare round trip of the same command, for the figure printed below.
  const TimePoint b0 = SteadyClock().Now();
  for (const auto& f : PanFrames(kFrames, Duration(0))) client_->Execute(f.command);
  const Duration bare = SteadyClock().Now() - b0;

  std::size_t replies = 0;
  const TimePoint t0 = SteadyClock().Now();
  const RunReport report = RunFrames(
      *client_, PanFrames(kFrames, Duration(0)), {.mode = CommandMode::kDirect, .paced = true},
      [&](std::size_t, const Reply& r) { replies += r.signal == Signal::kSuccess; }, nullptr);
  const Duration took = SteadyClock().Now() - t0;
  EXPECT_EQ(replies, kFrames);
  EXPECT_EQ(report.signal, 0);
  std::printf("direct: %.2f ms a frame; bare Execute round trip: %.2f ms\n", ToSeconds(took) * 1e3 / kFrames,
              ToSeconds(bare) * 1e3 / kFrames);
  EXPECT_LT(took, milliseconds(500)) << "a 20 ms polling slice per frame would take >= 1 s";
}

TEST_F(SequenceRunnerTest, DelayModeReportsEveryReplyInTheOrderGivenWithProgress) {
  std::vector<std::size_t> order;
  int progress = 0;
  const RunReport report = RunFrames(
      *client_, PanFrames(6, milliseconds(40)), {.mode = CommandMode::kDelay, .delay = milliseconds(50)},
      [&](std::size_t i, const Reply& r) {
        EXPECT_EQ(r.signal, Signal::kSuccess) << r.message;
        order.push_back(i);
      },
      [&](const RunProgress& p) {
        EXPECT_EQ(p.total, 6u);
        ++progress;
      });
  EXPECT_EQ(order, (std::vector<std::size_t>{0, 1, 2, 3, 4, 5}));
  ASSERT_EQ(report.replies.size(), 6u);
  for (const auto& r : report.replies) EXPECT_TRUE(r.has_value());
  EXPECT_GT(progress, 0);
  EXPECT_TRUE(report.unknown_outcomes.empty());
}

TEST_F(SequenceRunnerTest, AStopRequestEndsADelaySequenceAndStopsTheFramesQueuedOnTheServer) {
  std::size_t answered = 0;
  // 20 frames 100 ms apart, all sent at once, 0.2 s ahead: the stop comes
  // after the first reply, while most frames wait on the server.
  const RunReport report =
      RunThenStop(PanFrames(20, milliseconds(100)),
                  {.mode = CommandMode::kDelay, .delay = milliseconds(200), .paced = false}, 1, answered);
  EXPECT_EQ(answered, 1u);
  EXPECT_NE(report.interrupt_note.find("STOP sent to pioneer"), std::string::npos) << report.interrupt_note;
  EXPECT_NE(report.interrupt_note.find("frames already queued on the server each get a STOP"),
            std::string::npos)
      << report.interrupt_note;
}

// Before, a playback run was left on an abandoned thread and the process had
// to _Exit; now RunSequence itself ends on the stop request.
TEST_F(SequenceRunnerTest, AStopRequestEndsAPlaybackSequenceWithoutLeavingAThreadBehind) {
  std::size_t answered = 0;
  const TimePoint t0 = SteadyClock().Now();
  const RunReport report = RunThenStop(PanFrames(20, milliseconds(100)),
                                       {.mode = CommandMode::kPlayback, .paced = false}, 1, answered);
  EXPECT_EQ(answered, 1u);
  EXPECT_LT(SteadyClock().Now() - t0, seconds(1)) << "the 1.9 s sequence was waited for";
  EXPECT_NE(report.interrupt_note.find("playback frames already queued on the server stay queued"),
            std::string::npos)
      << report.interrupt_note;
}

TEST_F(SequenceRunnerTest, AStopRequestEndsADirectSequenceBeforeItsNextFrame) {
  std::size_t answered = 0;
  const RunReport report =
      RunThenStop(PanFrames(10, milliseconds(200)), {.mode = CommandMode::kDirect}, 2, answered);
  EXPECT_EQ(answered, 2u);
  ASSERT_EQ(report.replies.size(), 10u);
  EXPECT_TRUE(report.replies[1].has_value());
  EXPECT_FALSE(report.replies[2].has_value());
  EXPECT_NE(report.interrupt_note.find("the frames not yet sent were not sent"), std::string::npos)
      << report.interrupt_note;
}

// The library's default (no hooks) is unchanged: every reply, in the order given.
TEST_F(SequenceRunnerTest, RunSequenceWithoutHooksReturnsEveryReplyInTheOrderGiven) {
  std::vector<TimedCommand> frames = PanFrames(4, milliseconds(30));
  std::swap(frames[0], frames[3]);  // out of time order
  const SequenceResult r =
      client_->RunSequence(frames, {.mode = CommandMode::kDelay, .delay = milliseconds(50)});
  ASSERT_EQ(r.replies.size(), 4u);
  for (const Reply& reply : r.replies) EXPECT_NE(reply.id, 0);
  EXPECT_LT(r.replies[3].exec_time, r.replies[0].exec_time);  // frame 3 has offset 0
  EXPECT_FALSE(r.stopped);
  EXPECT_EQ(r.frames_sent, 4u);
}

// Review of issue 20: without on_progress, the waits woke at a progress time
// left in the past and spun: a 1 s delay sequence took about 1 s of CPU.
TEST_F(SequenceRunnerTest, RunSequenceWithoutHooksWaitsWithoutSpinning) {
  const auto thread_cpu = [] {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  };
  const double before = thread_cpu();
  const SequenceResult r = client_->RunSequence(PanFrames(5, milliseconds(200)),
                                                {.mode = CommandMode::kDelay, .delay = milliseconds(200)});
  const double used = thread_cpu() - before;
  ASSERT_EQ(r.replies.size(), 5u);
  EXPECT_LT(used, 0.1) << "the caller's thread used " << used << " s of CPU over a 1 s sequence";
}

}  // namespace
}  // namespace robotalk::cli

// The server log's limiter (robotalk/log_limiter.h, its own tests in
// tests/core/log_limiter_test.cpp) in a ServerDaemon whose driver fails in
// every Update (issue 19: 231 fault lines in 12 s).
#include "robotalk/log_limiter.h"

#include "fake_driver.h"
#include "robot_daemon.h"
#include "robotalk/channels.h"
#include "robotalk/forwarding_transport.h"
#include "robotalk/log_writer.h"
#include "robotalk/memory_transport.h"
#include "robotalk/request.h"
#include "server_daemon.h"
#include "session_test_util.h"
#include "support/test_clients.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <functional>
#include <iterator>
#include <mutex>
#include <regex>
#include <sstream>
#include <thread>

namespace robotalk {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using ::testing::HasSubstr;

class FailingUpdateDriver final : public testing::FakeDriver {
 public:
  using FakeDriver::FakeDriver;
  void Update(TimePoint, std::vector<Completion>&) override { throw std::runtime_error("CAN bus timeout"); }
};

TEST(ServerDaemonLog, ADriverFailingInEveryUpdateLogsItsFaultOnceAndThenASummary) {
  ManualClock clock;
  auto bus = std::make_shared<MemoryBus>();
  MemoryTransport transport(bus);
  RobotDaemon robot("bot", "fake", std::make_unique<FailingUpdateDriver>(testing::PanRobot()), clock);
  ::testing::internal::CaptureStderr();
  {
    ServerDaemon server(transport, clock, ServerDaemonOptions{.server_id = 7, .fifo_priority = 0});
    server.AddRobot(robot, SessionOptions{});
    const TimePoint end = clock.Now() + seconds(12);
    while (clock.Now() < end) {  // the driver's 10 ms period
      robot.RunOnce(clock.Now());
      server.RunOnce(Duration(0));
      clock.Advance(milliseconds(10));
    }
  }
  const std::string log = ::testing::internal::GetCapturedStderr();
  std::istringstream lines(log);
  std::vector<std::string> faults;
  for (std::string line; std::getline(lines, line);) {
    if (line.find("DRIVER FAULT") != std::string::npos) faults.push_back(line);
  }
  ASSERT_FALSE(faults.empty()) << log;
  EXPECT_LE(faults.size(), 3u) << log;
  EXPECT_THAT(faults[0], HasSubstr("driver 'fake' threw in Update: CAN bus timeout"));
  EXPECT_THAT(faults[1], HasSubstr("(repeated "));
  EXPECT_TRUE(robot.in_panic());
}

// Publishes through `inner`; `before` sees every message just before it leaves.
class WatchedTransport final : public ForwardingTransport {
 public:
  using Before = std::function<void(const std::string&, std::span<const std::uint8_t>)>;
  WatchedTransport(Transport& inner, Before before)
      : ForwardingTransport(inner), before_(std::move(before)) {}
  void Publish(const std::string& channel, std::span<const std::uint8_t> bytes) override {
    before_(channel, bytes);
    inner().Publish(channel, bytes);
  }

 private:
  Before before_;
};

// A ServerDaemon serving one robot with audit lines (--log-executions),
// stepped by hand: the server, the robot, the server again, then 10 ms on.
struct AuditedBot {
  AuditedBot(Transport& transport, ManualClock& clock)
      : clock(clock),
        robot("bot", "fake", std::make_unique<testing::FakeDriver>(testing::PanRobot()), clock,
              RobotDaemonOptions{.log_executions = true}),
        server(transport, clock, ServerDaemonOptions{.server_id = 7, .fifo_priority = 0}) {
    server.AddRobot(robot, SessionOptions{});
  }
  void Step() {
    server.RunOnce(Duration(0));
    robot.RunOnce(clock.Now());
    server.RunOnce(Duration(0));
    clock.Advance(milliseconds(10));
  }
  ManualClock& clock;
  RobotDaemon robot;  // outlives the server
  ServerDaemon server;
};

// soak.md: the audit line (--log-executions) of a command is on stderr
// before its reply leaves, so a reply never exists without its line (a
// server killed in between would leave the soak's checker a reply it cannot
// explain). Stderr is captured to a file; at each reply package's publish
// the file must already hold the line of every reply in it.
TEST(ServerDaemonLog, AnAuditLineIsWrittenBeforeItsReplyLeaves) {
  ManualClock clock;
  auto bus = std::make_shared<MemoryBus>();
  MemoryTransport server_end(bus);
  MemoryTransport client(bus);
  std::vector<std::string> without_line;
  std::size_t replies = 0;
  WatchedTransport watched(server_end, [&](const std::string& channel, std::span<const std::uint8_t> bytes) {
    if (channel.find("/REPLY/") == std::string::npos) return;
    std::ifstream captured("/proc/self/fd/2");  // what stderr holds now
    const std::string written((std::istreambuf_iterator<char>(captured)), std::istreambuf_iterator<char>());
    for (const Reply& r : DecodeReplyBatch(bytes).replies) {
      ++replies;
      if (written.find("command " + std::to_string(r.id) + " ") == std::string::npos)
        without_line.push_back(std::to_string(r.id) + " " + std::string(ToString(r.signal)));
    }
  });
  ::testing::internal::CaptureStderr();
  {
    AuditedBot bot(watched, clock);
    const auto step = [&] { bot.Step(); };
    const std::int64_t session = testing::SayHello(client, "bot", testing::kAlice, step).session_id;
    Request r{.client_id = testing::kAlice, .session_id = session, .sequence = 1};
    r.commands.push_back(Command{1, CommandType::kJointSetPoint, std::nullopt, "pan", {0.5}});
    r.commands.push_back(Command{2, CommandType::kJointSetPoint, std::nullopt, "pan", {2.0}});  // MODIFIED
    client.Publish(RequestChannel("bot"), EncodeRequest(r));
    for (int i = 0; i < 5; ++i) step();
  }
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(replies, 2u) << log;
  EXPECT_THAT(without_line, ::testing::IsEmpty()) << "replies that left before their audit line\n" << log;
}

}  // namespace
}  // namespace robotalk

namespace robotalk {
namespace {

// Stderr as a pipe that is full and never read: a supervisor that keeps the
// pipe but never drains it, or a terminal stopped with Ctrl-S. Restores the
// old stderr (and drains the pipe, so whatever blocked on it ends) when done.
class FullStderr {
 public:
  FullStderr() {
    int fds[2];
    if (pipe(fds) != 0) throw std::runtime_error("pipe");
    read_end_ = fds[0];
    const int flags = fcntl(fds[1], F_GETFL);
    fcntl(fds[1], F_SETFL, flags | O_NONBLOCK);
    const std::string chunk(4096, 'x');
    while (write(fds[1], chunk.data(), chunk.size()) > 0) {
    }
    fcntl(fds[1], F_SETFL, flags);  // blocking again, as stderr is
    saved_ = dup(2);
    dup2(fds[1], 2);
    close(fds[1]);
  }
  ~FullStderr() { Release(); }
  /// Reads the pipe until `done()` (whatever blocked on it goes on), then
  /// restores stderr.
  std::string Release(const std::function<bool()>& done = [] { return true; }) {
    std::string text;
    if (saved_ < 0) return text;
    fcntl(read_end_, F_SETFL, fcntl(read_end_, F_GETFL) | O_NONBLOCK);
    char buffer[4096];
    const auto drain = [&] {
      for (ssize_t n; (n = read(read_end_, buffer, sizeof buffer)) > 0;) text.append(buffer, n);
    };
    do {
      drain();
      std::this_thread::sleep_for(milliseconds(1));
    } while (!done());
    dup2(saved_, 2);
    close(saved_);
    saved_ = -1;
    drain();
    close(read_end_);
    return text;
  }

 private:
  int read_end_ = -1;
  int saved_ = -1;
};

// A stderr that takes nothing (full, never read) never stops the
// ServerDaemon. With --log-executions every command's audit line waits for
// stderr; before, the ServerDaemon waited with it, in fprintf, for as long as
// stderr took nothing: no panic was taken, no watchdog ran, no reply left.
// A panic sent while stderr takes nothing is taken.
TEST(ServerDaemonLog, AStderrThatTakesNothingNeverKeepsAPanicFromBeingTaken) {
  ManualClock clock;
  auto bus = std::make_shared<MemoryBus>();
  MemoryTransport server_end(bus);
  MemoryTransport client(bus);
  AuditedBot bot(server_end, clock);
  const auto step = [&] { bot.Step(); };
  const std::int64_t session = testing::SayHello(client, "bot", testing::kAlice, step).session_id;
  Request r{.client_id = testing::kAlice, .session_id = session, .sequence = 1};
  for (int i = 0; i < 20; ++i) {  // 20 audit lines for a stderr that takes none
    r.commands.push_back(Command{i + 1, CommandType::kJointSetPoint, std::nullopt, "pan", {0.01 * i}});
  }
  client.Publish(RequestChannel("bot"), EncodeRequest(r));  // before the steps: its session is live
  FullStderr full;
  std::atomic<bool> stop{false};
  std::atomic<bool> stepping_ended{false};
  std::thread stepping([&] {
    while (!stop) step();
    stepping_ended = true;
  });
  std::this_thread::sleep_for(milliseconds(300));  // the ServerDaemon meets the full stderr
  client.Publish(RequestChannel("bot"),
                 EncodeRequest(Request{.client_id = testing::kBob, .sequence = 1, .panic = true}));
  const auto deadline = std::chrono::steady_clock::now() + seconds(5);
  while (!bot.robot.in_panic() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(milliseconds(10));
  const bool taken = bot.robot.in_panic();
  stop = true;
  full.Release([&] { return stepping_ended.load(); });
  stepping.join();
  EXPECT_TRUE(taken) << "a panic sent while stderr took nothing was not taken within 5 s";
}

// The LogWriter under a stderr that takes nothing: a Write returns without
// its lines written; what waits is bounded (kMaxQueuedBytes), the rest
// dropped and counted; once stderr takes lines again, the first says how many
// were lost, and the lines after are written.
TEST(LogWriterTest, AStderrThatTakesNothingBoundsTheQueueAndSaysWhatWasLostOnceItTakesLinesAgain) {
  FullStderr full;
  LogWriter log("test: ");
  std::vector<std::string> lines{"first"};
  EXPECT_FALSE(log.Write(lines)) << "written to a full pipe nobody reads";
  EXPECT_TRUE(lines.empty());
  for (int i = 0; i < 6000; ++i) lines.push_back(std::string(1000, 'a'));  // 6 MB
  EXPECT_FALSE(log.Write(lines));
  const std::uint64_t dropped = log.dropped();
  EXPECT_GT(dropped, 6000u - LogWriter::kMaxQueuedBytes / 1000) << "more than the bound waits";
  EXPECT_LT(dropped, 6000u);
  std::atomic<bool> after_written{false};
  std::thread after([&] {
    std::vector<std::string> line{"after"};
    while (!log.Write(line)) {  // each "after" that found the queue full is dropped too
      std::this_thread::sleep_for(milliseconds(10));
      line = {"after"};
    }
    after_written = true;
  });
  const std::string text = full.Release([&] { return after_written.load(); });
  after.join();
  EXPECT_THAT(text, HasSubstr("test: first\n"));
  std::smatch lost;
  ASSERT_TRUE(std::regex_search(text, lost, std::regex("test: ([0-9]+) log lines lost")))
      << text.substr(0, 300);
  EXPECT_GE(std::stoull(lost[1]), dropped);
  EXPECT_THAT(text, HasSubstr("test: after\n"));
}

// Review 12: a stderr whose description is non-blocking (one another
// process set O_NONBLOCK on: ssh does on the stdio it shares, so does node
// on a terminal) answers EAGAIN while its reader is merely behind. The
// LogWriter took that for a write that failed and lost the lines (counted
// as lost), though the reader took them a moment later; it now waits for
// the descriptor to take more, as a blocking one makes it wait.
TEST(LogWriterTest, ANonBlockingStderrWhoseReaderIsBehindLosesNothing) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  fcntl(fds[1], F_SETFL, fcntl(fds[1], F_GETFL) | O_NONBLOCK);
  std::string text;
  std::thread reader([&] {
    std::this_thread::sleep_for(milliseconds(300));  // behind: the pipe (64 KiB) fills first
    char buffer[4096];
    for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, n);
  });
  {
    LogWriter log("test: ", fds[1]);
    std::vector<std::string> lines;
    for (int i = 0; i < 200; ++i) lines.push_back("line " + std::to_string(i) + " " + std::string(1000, 'a'));
    log.Write(lines);  // 200 kB: more than the pipe holds
    std::vector<std::string> last{"last"};
    log.Write(last);
    const auto deadline = std::chrono::steady_clock::now() + seconds(10);
    for (std::vector<std::string> none; !log.Write(none) && std::chrono::steady_clock::now() < deadline;)
      std::this_thread::sleep_for(milliseconds(10));  // until everything queued is written, or lost
    EXPECT_EQ(log.dropped(), 0u);
  }
  close(fds[1]);  // the writer thread wrote everything: "last" came after the rest
  reader.join();
  close(fds[0]);
  int lost = 0;
  for (int i = 0; i < 200; ++i)
    lost += text.find("test: line " + std::to_string(i) + " ") == std::string::npos;
  EXPECT_EQ(lost, 0) << "of 200 lines; " << text.size() << " bytes read";
  EXPECT_EQ(text.find("log lines lost"), std::string::npos);
  EXPECT_NE(text.find("test: last\n"), std::string::npos);
}

// Review 12: a log line carries texts of anyone's (robotalk-ros2 logs a
// refused JointTrajectory's joint name, from anyone on the DDS domain): a
// line break in one forged a whole log line, a terminal escape reached the
// terminal. Every line is written on one line, its control characters (C0,
// DEL, C1 encoded in UTF-8) as \xNN; UTF-8 text is kept.
TEST(LogWriterTest, ALinesControlCharactersAreWrittenEscapedOnOneLine) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  {
    LogWriter log("test: ", fds[1]);
    std::vector<std::string> lines{
        "joint 'h\xc3\xa4nd\nrobotalk-server: robot 'bot': executed'\x1b]0;x\x07\xc2\x9b"};
    ASSERT_TRUE(log.Write(lines));
  }
  close(fds[1]);
  std::string text;
  char buffer[4096];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, n);
  close(fds[0]);
  EXPECT_EQ(text,
            "test: joint 'h\xc3\xa4nd\\x0arobotalk-server: robot 'bot': executed'\\x1b]0;x\\x07\\xc2\\x9b\n");
}

// Lines whose write failed (a descriptor that refused them for a moment: a
// non-blocking pipe that was full, a full disk) are counted and said by the
// next write; a writer that ends with no write after says them in a last line
// of its own (before: the count was dropped with the writer).
TEST(LogWriterTest, LinesLostAndNotYetSaidAreSaidInALastLineWhenTheWriterEnds) {
  // The writer's descriptor is first a full disk (/dev/full: ENOSPC), then
  // a pipe (dup2 onto the same number): the lines refused, then room again.
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  fcntl(fds[0], F_SETFL, fcntl(fds[0], F_GETFL) | O_NONBLOCK);
  const int log_fd = open("/dev/full", O_WRONLY | O_CLOEXEC);
  ASSERT_GE(log_fd, 0);
  {
    LogWriter log("test: ", log_fd);
    std::vector<std::string> lines{"refused", "refused too"};
    log.Write(lines);                         // the full disk refuses them: two lines lost
    ASSERT_EQ(dup2(fds[1], log_fd), log_fd);  // room again; nothing else is written
  }
  char buffer[4096];
  std::string text;
  for (int i = 0; i < 100 && text.find('\n') == std::string::npos; ++i) {  // the writer's thread writes it
    for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, n);
    if (text.find('\n') == std::string::npos) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_THAT(text, HasSubstr("test: 2 log lines lost")) << text.substr(0, 300);
  close(fds[0]);
  close(fds[1]);
  close(log_fd);
}

// Review 13: a process forked after its LogWriter started (robotalk-walk-sweep
// forks a child per push; each child's ODE and driver notes go through
// LogWriter::Stderr()) has no writer thread in the child: every line there
// waited kMaxWait and was lost, and a fork while the writer thread held its
// lock left the child's first Write waiting for ever. The child has a writer
// of its own, which writes the child's lines, never the parent's again.
TEST(LogWriterTest, AChildForkedAfterTheWriterStartedWritesItsOwnLinesOnce) {
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  std::string text;
  {
    LogWriter log("test: ", fds[1]);
    ASSERT_TRUE(log.Write(std::string("parent before")));
    std::fflush(nullptr);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      const bool written = log.Write(std::string("child"));
      _exit(written && log.Flush() ? 0 : 1);
    }
    int status = -1;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the child's Write returned false";
    ASSERT_TRUE(log.Write(std::string("parent after")));
  }
  close(fds[1]);
  char buffer[4096];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, n);
  close(fds[0]);
  EXPECT_EQ(text, "test: parent before\ntest: child\ntest: parent after\n");
}

TEST(SplitLines, KeepsEmptyLinesAndNoneAfterALastLineBreak) {
  EXPECT_EQ(SplitLines("usage:\n\n  a\nb\n"), (std::vector<std::string>{"usage:", "", "  a", "b"}));
  EXPECT_EQ(SplitLines("one"), (std::vector<std::string>{"one"}));
  EXPECT_TRUE(SplitLines("").empty());
}

}  // namespace
}  // namespace robotalk

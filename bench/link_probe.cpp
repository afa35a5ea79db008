// robotalk-bench-link: the client side of tests/integration/link_relay_test.sh
// and of scripts/bench.sh's "links" figure (issue 23). Through robotalk-lcm-relay,
//   robotalk-bench-link URL ROBOT health N PERIOD_MS
//     sends N JOINT_STATE queries, one package every PERIOD_MS, waits for
//     their replies, then prints the session's SERVER_COUNTERS as NAME=VALUE
//     lines;
//   robotalk-bench-link URL ROBOT stall MAX_LATE
//     a teleoperation stream of 'pan' set-points, one every 20 ms in delay
//     mode (start = server clock + 60 ms when sent), that stalls for 5 s and
//     then sends the frames it held in a burst, then 1 s more on time.
//     MAX_LATE: the packages' max_late in seconds, "default" (the robot's
//     --max-late) or "never". Prints one line per frame: "frame K PART SIGNAL
//     LATENESS_S" (PART = before, burst, after), then the counters.
//   robotalk-bench-link URL ROBOT deadlines N SEED
//     N 'pan' set-points in delay mode, 50 per package every 10 ms, starting
//     between 0.3 s before and 0.05 s after the server clock when sent (a
//     sawtooth, rising: see Deadlines): about half are past the robot's
//     deadline when they arrive. Prints
//     commands, executed, expired, other, and violations = executed later
//     than the deadline (0.1 s + the wire's microsecond rounding).
// Exits 1 when the robot does not answer.
#include "robotalk/robot_client.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <exception>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

using namespace robotalk;

namespace {

void PrintCounters(RobotClient& client) {
  const Reply r = client.ServerCounters();
  std::istringstream names(r.message);
  std::string name;
  for (std::size_t i = 0; names >> name && i < r.values.size(); ++i)
    std::printf("%s=%.9g\n", name.c_str(), r.values[i]);
}

int Health(RobotClient& client, int n, int period_ms) {
  std::vector<PendingReply> pending;
  const auto period = std::chrono::milliseconds(period_ms);
  auto next = std::chrono::steady_clock::now();
  for (int i = 0; i < n; ++i) {
    pending.push_back(client.SendQuery(robotalk::Query{.type = QueryType::kJointState}));
    next += period;
    std::this_thread::sleep_until(next);
  }
  int failed = 0;
  for (PendingReply& p : pending) {
    try {
      p.Wait(std::chrono::seconds(5));
    } catch (const std::exception&) {
      ++failed;
    }
  }
  std::printf("queries=%d unanswered=%d\n", n, failed);
  PrintCounters(client);
  return 0;
}

int Stall(RobotClient& client) {
  constexpr int kBefore = 50, kStall = 250, kAfter = 50;  // 1 s, 5 s, 1 s at 50 Hz
  const Duration frame = std::chrono::milliseconds(20), ahead = std::chrono::milliseconds(60);
  const TimePoint t0 = client.ServerNow() + std::chrono::milliseconds(200);
  const auto make = [&](int k) {
    Command c;
    c.type = CommandType::kJointSetPoint;
    c.target = "pan";
    c.values = {0.3 * std::sin(0.05 * k)};
    c.start_time = StartTime::At(t0 + k * frame);
    return c;
  };
  std::vector<PendingReply> replies;
  const auto send_on_time = [&](int k) {
    // Sent `ahead` before its start on the server clock.
    while (client.ServerNow() < t0 + k * frame - ahead)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    for (PendingReply& p : client.SendBatch({make(k)}, CommandMode::kDelay)) replies.push_back(std::move(p));
  };
  for (int k = 0; k < kBefore; ++k) send_on_time(k);
  // The stall: nothing leaves for 5 s; then the held frames in a burst.
  const int first_after = kBefore + kStall;
  while (client.ServerNow() < t0 + first_after * frame - ahead)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  for (int k = kBefore; k < first_after; k += 25) {
    std::vector<Command> batch;
    for (int j = k; j < std::min(k + 25, first_after); ++j) batch.push_back(make(j));
    for (PendingReply& p : client.SendBatch(std::move(batch), CommandMode::kDelay))
      replies.push_back(std::move(p));
  }
  for (int k = first_after; k < first_after + kAfter; ++k) send_on_time(k);
  for (std::size_t k = 0; k < replies.size(); ++k) {
    const char* part = k < kBefore ? "before" : k < static_cast<std::size_t>(first_after) ? "burst" : "after";
    try {
      const Reply r = replies[k].Wait(std::chrono::seconds(10));
      std::printf("frame %zu %s %s %.6f\n", k, part, std::string(ToString(r.signal)).c_str(),
                  ToSeconds(r.lateness));
    } catch (const std::exception& e) {
      std::printf("frame %zu %s NONE 0\n", k, part);
    }
  }
  PrintCounters(client);
  return 0;
}

int Deadlines(RobotClient& client, int n, unsigned seed) {
  // Command k starts at base + k * 0.2 ms + offset_k, offset_k a triangle
  // wave between -0.3 s and +0.05 s with a 1 s period (5000 commands): the
  // starts rise monotonically (no command is superseded by a later one that
  // already ran, docs/protocol.md) and, sent at 5000 a second, about half
  // arrive past the robot's 0.1 s deadline. SEED shifts the phase.
  const double phase = static_cast<double>(seed % 1000) / 1000.0;
  const TimePoint base = client.ServerNow();
  long executed = 0, expired = 0, other = 0, violations = 0, unanswered = 0;
  double max_executed_lateness = 0;
  // Replies are collected as the stream goes (the client keeps at most
  // ClientOptions::return_cache_capacity uncollected ones).
  std::deque<PendingReply> waiting;
  const auto collect = [&](PendingReply& p) {
    try {
      const Reply r = p.Wait(std::chrono::seconds(20));
      if (r.signal == Signal::kSuccess || r.signal == Signal::kModified) {
        ++executed;
        max_executed_lateness = std::max(max_executed_lateness, ToSeconds(r.lateness));
        if (r.lateness > std::chrono::microseconds(100'001)) ++violations;
      } else if (r.signal == Signal::kInterrupted && r.message.starts_with("expired:")) {
        ++expired;
      } else {
        ++other;
      }
    } catch (const std::exception&) {
      ++unanswered;
    }
  };
  auto next = std::chrono::steady_clock::now();
  for (int sent = 0; sent < n;) {
    std::vector<Command> batch;
    for (int j = 0; j < 50 && sent < n; ++j, ++sent) {
      Command c;
      c.type = CommandType::kJointSetPoint;
      c.target = "pan";
      c.values = {0.001 * (sent % 100)};
      const double x = std::fmod(phase + sent / 5000.0, 1.0);
      const double offset = -0.3 + 0.35 * (1 - std::abs(2 * x - 1));
      c.start_time = StartTime::At(base + FromSeconds(0.0002 * sent + offset));
      batch.push_back(std::move(c));
    }
    for (PendingReply& p : client.SendBatch(std::move(batch), CommandMode::kDelay))
      waiting.push_back(std::move(p));
    while (waiting.size() > 2000) {
      collect(waiting.front());
      waiting.pop_front();
    }
    next += std::chrono::milliseconds(10);
    std::this_thread::sleep_until(next);
  }
  for (PendingReply& p : waiting) collect(p);
  std::printf(
      "commands=%d\nexecuted=%ld\nexpired=%ld\nother=%ld\nunanswered=%ld\nviolations=%ld\n"
      "max_executed_lateness_s=%.6f\n",
      n, executed, expired, other, unanswered, violations, max_executed_lateness);
  PrintCounters(client);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(
        stderr,
        "usage: robotalk-bench-link URL ROBOT health N PERIOD_MS | stall MAX_LATE | deadlines N SEED\n");
    return 2;
  }
  try {
    ClientOptions options;
    options.lcm_url = argv[1];
    options.connect_timeout = std::chrono::seconds(10);
    const std::string what = argv[3];
    if (what == "stall" && argc > 4) {
      const std::string limit = argv[4];
      options.max_late = limit == "never"     ? kMaxLateNever
                         : limit == "default" ? kMaxLateServerDefault
                                              : FromSeconds(std::atof(limit.c_str()));
    }
    RobotClient client(options);
    client.Connect(argv[2]);
    if (what == "health" && argc == 6) return Health(client, std::atoi(argv[4]), std::atoi(argv[5]));
    if (what == "stall") return Stall(client);
    if (what == "deadlines" && argc == 6)
      return Deadlines(client, std::atoi(argv[4]), static_cast<unsigned>(std::atoi(argv[5])));
    std::fprintf(stderr, "robotalk-bench-link: unknown '%s'\n", what.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robotalk-bench-link: %s\n", e.what());
    return 1;
  }
}

// robotalk-bench-raw sessions: K client sessions of one robot, idle or under
// one of the well-formed exhaustion loads of issue 19 (item 8), for the
// server's memory figure (docs/performance.md, "Memory").
//
//   robotalk-bench-raw sessions --url U --robot R --count K --seconds S
//       [--load none|unknown|playbacks|queue] [--packages N] [--server-pid P]
//
// Each session says hello (open mode) and then, round-robin over the
// sessions so none goes silent past the watchdog, sends its load:
//   unknown    N packages of 300 JOINT_SETPOINTs naming 200-byte unknown joints
//              (every reply an ERROR the reply cache keeps)
//   playbacks  N playback sequences of 5 frames, each finished at once
//   queue      N packages of 250 STOPs due in 30 minutes (10,000 a session at
//              N = 40: the --max-queue default)
// (within S seconds), then heartbeats for 1.5 s (idle: until S seconds have
// passed). With --server-pid it then reads the server's VmRSS and VmHWM, and
// (queue) whether a new client's command is still admitted. Prints one JSON line; every loop is
// bounded in count and time.
#include "sessions_bench.h"

#include "robotalk/channels.h"
#include "robotalk/request.h"
#include "robotalk/routed_lcm_transport.h"

#include <fstream>
#include <map>
#include <optional>
#include <random>
#include <thread>

namespace robotalk::bench {
namespace {

constexpr std::int64_t kFirstClient = 0x5e55000000000000;

// VmRSS or VmHWM of `pid` in KiB (-1 when unreadable).
double StatusKb(long pid, const std::string& field) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1));
  }
  return -1;
}

TimePoint Now() { return TimePoint(std::chrono::nanoseconds(MonoNs())); }

// The load of one session's `index`-th package (nullopt: that load is done).
std::optional<Request> LoadPackage(const std::string& load, long index, long packages, CommandId& next_id) {
  if (index >= packages) return std::nullopt;
  Request r;
  if (load == "unknown") {
    for (int i = 0; i < 300; ++i) {
      r.commands.push_back(Command{next_id++,
                                   CommandType::kJointSetPoint,
                                   StartTime::Now(),
                                   std::string(200, 'j') + std::to_string(i),
                                   {0.1}});
    }
  } else if (load == "playbacks") {
    r.mode = RequestMode::kPlayback;
    r.playback = {.id = next_id++, .frames = 5, .duration = std::chrono::milliseconds(4)};
    for (int f = 0; f < 5; ++f) {
      r.commands.push_back(
          Command{next_id++, CommandType::kStop, StartTime::After(std::chrono::milliseconds(f)), "", {}});
    }
  } else if (load == "queue") {
    const TimePoint later = Now() + std::chrono::minutes(30);
    for (int i = 0; i < 250; ++i) {
      r.commands.push_back(Command{next_id++, CommandType::kStop, StartTime::At(later), "", {}});
    }
  } else {
    return std::nullopt;
  }
  return r;
}

}  // namespace

int Sessions(const Args& a) {
  const std::string robot = a.Str("robot", "pioneer");
  const std::string load = a.Str("load", "none");
  const long packages = a.Int("packages", 0);
  const long server_pid = a.Int("server-pid", 0);
  const auto transport = OpenLcmTransport(a.Str("url", ""), OpenLcmOptions{.all_lanes = true});
  const long k = a.Int("count", 100);
  const std::int64_t end = MonoNs() + static_cast<std::int64_t>(a.Num("seconds", 5) * 1e9);
  std::map<std::int64_t, std::int64_t> session_of;  // client id -> session id
  std::string refusal;
  const auto sub = transport->Subscribe(HelloChannel(robot) + "/.*",  // every client's HELLO/<client> answer
                                        [&](const std::string&, std::span<const std::uint8_t> bytes) {
                                          const HelloAnswer answer = DecodeHelloAnswer(bytes);
                                          if (answer.session_id > 0) {
                                            session_of[answer.body.client_id] = answer.session_id;
                                          } else if (refusal.empty()) {
                                            refusal = answer.refusal;
                                          }
                                        });
  std::mt19937_64 rng(7);
  const auto hello = [&](std::int64_t client) {
    Hello h;
    h.body.client_id = client;
    for (auto& b : h.body.client_nonce) b = static_cast<std::uint8_t>(rng());
    transport->Publish(HelloChannel(robot), EncodeHello(h));
  };
  for (long i = 0; i < k; ++i) {
    hello(kFirstClient + i + 1);
    if (i % 50 == 49) transport->HandleFor(std::chrono::milliseconds(2));  // ~40 ms per 1000
  }
  for (int i = 0; i < 100 && static_cast<long>(session_of.size()) < k; ++i)
    transport->HandleFor(std::chrono::milliseconds(20));
  if (!refusal.empty()) std::fprintf(stderr, "sessions: a hello was refused: %s\n", refusal.c_str());

  const std::string channel = RequestChannel(robot);
  std::map<std::int64_t, std::int64_t> sequence;  // client id -> last sequence sent
  const auto send = [&](std::int64_t client, Request r) {
    r.client_id = client;
    r.session_id = session_of.at(client);
    r.sequence = ++sequence[client];
    r.send_time = Now();
    transport->Publish(channel, EncodeRequest(r));
  };
  // The load, round-robin: package i of every session, then i + 1.
  const std::int64_t load_start = MonoNs();
  CommandId next_id = 1;
  long sent_packages = 0;
  for (long i = 0; i < packages && MonoNs() < end; ++i) {
    for (const auto& [client, session] : session_of) {
      std::optional<Request> r = LoadPackage(load, i, packages, next_id);
      if (!r) break;
      send(client, std::move(*r));
      ++sent_packages;
      // Paced (the server's receive buffer): the small playback packages ten at a time.
      if (load != "playbacks" || sent_packages % 10 == 0)
        transport->HandleFor(std::chrono::microseconds(500));
    }
  }
  const double load_s = static_cast<double>(MonoNs() - load_start) / 1e9;
  // Heartbeats (an empty package, as an idle RobotClient sends) keep every
  // session open: until --seconds have passed when idle, else 1.5 s after
  // the load; then the server's memory is read.
  std::int64_t heartbeats = 0;
  const std::int64_t hold_until = load == "none" ? end : MonoNs() + 1500000000;
  while (MonoNs() < hold_until) {
    const std::int64_t round = MonoNs();
    for (const auto& [client, session] : session_of) {
      send(client, Request{});
      if (++heartbeats % 50 == 0) transport->HandleFor(std::chrono::milliseconds(2));
    }
    while (MonoNs() < std::min(hold_until, round + 400000000))
      transport->HandleFor(std::chrono::milliseconds(50));
  }
  const double rss = server_pid > 0 ? StatusKb(server_pid, "VmRSS") : -1;
  const double hwm = server_pid > 0 ? StatusKb(server_pid, "VmHWM") : -1;
  const std::size_t opened = session_of.size();
  // A new client after the flood: is its command still admitted?
  double admitted = -1;
  if (load == "queue") {
    const std::int64_t legit = kFirstClient + k + 1;
    std::optional<ReplyBatch> answer;
    const auto replies =
        transport->Subscribe(ReplyChannel(robot, legit), [&](const std::string&, auto bytes) {
          ReplyBatch b = DecodeReplyBatch(bytes);
          if (b.ack_sequence == 1) answer = std::move(b);
        });
    hello(legit);
    for (int i = 0; i < 50 && !session_of.count(legit); ++i)
      transport->HandleFor(std::chrono::milliseconds(20));
    if (session_of.count(legit)) {
      CommandId id = next_id;
      Request r = *LoadPackage("queue", 0, 1, id);
      r.commands.resize(1);
      send(legit, std::move(r));
      for (int i = 0; i < 50 && !answer; ++i) transport->HandleFor(std::chrono::milliseconds(20));
      admitted = answer && answer->replies.empty() ? 1 : 0;  // queued: acknowledged, no refusal
      if (answer && !answer->replies.empty()) {
        std::fprintf(stderr, "sessions: the new client was refused: %s\n",
                     answer->replies[0].message.c_str());
      }
    }
  }
  PrintJson({Field("sessions", static_cast<double>(k)), Field("opened", static_cast<double>(opened)),
             Field("load_packages", static_cast<double>(sent_packages)), Field("load_s", load_s),
             Field("heartbeats", static_cast<double>(heartbeats)), Field("server_rss_kb", rss),
             Field("server_hwm_kb", hwm), Field("new_client_admitted", admitted)});
  return 0;
}

}  // namespace robotalk::bench

// robotalk-soak-client: one client of scripts/soak.sh (docs/soak.md), through
// the public RobotClient API only. It drives a robot in one mode for a
// bounded time and writes one JSON line per event to --out (flushed at once,
// so a client killed with SIGKILL leaves everything it knew):
//
//   {"ev":"hello","client":"<16 hex>","mode":"delay","seed":3}
//   {"ev":"sent","id":12,"type":"JOINT_SETPOINT","target":"pan","start_us":123}   start_us: server clock; -1
//   unknown
//   {"ev":"final","id":12,"outcome":"SUCCESS","msg":"..."}         a signal, UNKNOWN_OUTCOME,
//                                                                   TIMEOUT or CLIENT_ERROR
//   {"ev":"seq","after":11,"frames":8}    a playback sequence whose frames got ids above 11
//   {"ev":"seq_failed","after":11,"frames":8,"outcome":"UNKNOWN_OUTCOME","msg":"..."}
//   {"ev":"status","id":13,"outcome":"BUSY","kind":"not_ended","msg":"..."}  COMMAND_STATUS of a timed-out
//   sequence's ids
//   {"ev":"notsent","what":"...","msg":"..."}   a call that threw before anything was sent
//   {"ev":"panic"|"reset"|"samples"|"end", ...}
//
//   robotalk-soak-client --mode direct|delay|playback|watch|chaos --url U --robot R
//                        --seconds S --seed N --out FILE [--playback-copies 0|1|2]
//
// Every loop is bounded by --seconds (and each wait by the client's timeouts).
#include "bench_util.h"
#include "robotalk/channels.h"
#include "robotalk/command_status.h"
#include "robotalk/robot_client.h"

#include <atomic>
#include <memory>
#include <random>
#include <thread>
#include <utility>

using namespace robotalk;
using namespace robotalk::bench;

namespace {

// One JSON line per event, flushed (the process may be killed at any time).
class Report {
 public:
  explicit Report(const std::string& path) : f_(std::fopen(path.c_str(), "w")) {
    if (f_ == nullptr) throw std::runtime_error("cannot write " + path);
  }
  ~Report() { std::fclose(f_); }
  Report(const Report&) = delete;
  Report& operator=(const Report&) = delete;
  void Line(const Json& event) {
    std::fprintf(f_, "%s\n", robotalk::JsonText(event).c_str());
    std::fflush(f_);
  }

 private:
  std::FILE* f_;
};

// Messages are cut to 200 bytes: a line per event stays short.
std::string Short(const std::string& s) { return s.substr(0, 200); }

struct Soak {
  RobotClient& client;
  Report& report;
  std::mt19937_64 rng;
  TimePoint deadline;
  CommandId max_id = 0;  // the highest id this client has seen assigned
  bool panic_seen = false;

  double Uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  bool Running() const { return SteadyNow() < deadline; }
  static TimePoint SteadyNow() { return TimePoint(std::chrono::steady_clock::now().time_since_epoch()); }
  void Sleep(double s) { std::this_thread::sleep_for(FromSeconds(s)); }

  // A random motion command: set-points of the head, base speeds, short GOTOs.
  Command RandomCommand() {
    const double p = Uniform(0, 1);
    if (p < 0.45)
      return Command{.type = CommandType::kJointSetPoint, .target = "pan", .values = {Uniform(-2, 2)}};
    if (p < 0.7)
      return Command{.type = CommandType::kJointSetPoint, .target = "tilt", .values = {Uniform(-0.5, 0.4)}};
    if (p < 0.9)
      return Command{.type = CommandType::kSetSpeed, .values = {Uniform(-0.2, 0.2), Uniform(-0.3, 0.3)}};
    return Command{.type = CommandType::kGoto, .values = {Uniform(-0.3, 0.3), Uniform(-0.3, 0.3), 0.0}};
  }

  void Sent(CommandId id, const Command& c, std::int64_t start_us) {
    max_id = std::max(max_id, id);
    report.Line({{"ev", "sent"},
                 {"id", id},
                 {"type", ToString(c.type)},
                 {"target", c.target},
                 {"start_us", start_us}});
  }
  // exec_us: server clock when it ran (-1: no reply); late_us: how late after its start.
  void Final(CommandId id, const std::string& outcome, const std::string& msg, const Reply* r = nullptr) {
    if (r != nullptr && r->signal == Signal::kPanic) panic_seen = true;
    report.Line({{"ev", "final"},
                 {"id", id},
                 {"outcome", outcome},
                 {"exec_us", r ? ToWireMicros(r->exec_time) : -1},
                 {"late_us", r ? ToWireMicros(r->lateness) : -1},
                 {"msg", Short(msg)}});
  }
  // A client answered PANIC waits a little before trying again, as a real one would.
  void AfterPanic() {
    if (std::exchange(panic_seen, false)) Sleep(0.3);
  }
  void NotSent(const std::string& what, const std::string& msg) {
    report.Line({{"ev", "notsent"}, {"what", Short(what)}, {"msg", Short(msg)}});
  }

  // Waits for one reply and reports its outcome, whatever it is.
  void Collect(PendingReply& p, Duration wait) {
    try {
      const Reply r = p.Wait(wait);
      Final(p.id(), std::string(ToString(r.signal)), r.message, &r);
    } catch (const UnknownOutcomeError& e) {
      Final(p.id(), "UNKNOWN_OUTCOME", e.what());
    } catch (const TimeoutError& e) {
      Final(p.id(), "TIMEOUT", e.what());
    } catch (const Error& e) {
      Final(p.id(), "CLIENT_ERROR", e.what());
    }
  }

  // A client-side wait long enough that the library's own answer (a reply,
  // or UnknownOutcomeError after give_up_after) always comes first.
  Duration WaitFor(Duration until_start) const {
    return until_start + client.options().timeout + client.options().give_up_after + std::chrono::seconds(5);
  }
};

// Direct mode: one command at a time, each waiting for its final reply.
void RunDirect(Soak& s) {
  while (s.Running()) {
    const Command c = s.RandomCommand();
    try {
      const std::int64_t at = ToWireMicros(s.client.ServerNow());
      PendingReply p = s.client.Send(c);
      s.Sent(p.id(), c, at);
      s.Collect(p, s.WaitFor(Duration(0)));
    } catch (const Error& e) {
      s.NotSent(ToString(c.type), e.what());
      s.Sleep(0.2);
    }
    s.AfterPanic();
    s.Sleep(s.Uniform(0, 0.05));
  }
}

// Delay mode: sequences of timed commands on the server clock, 50 ms apart,
// starting 300 ms ahead, either in one package (a batch) or each frame in its
// own package when its time comes minus the delay (a live stream, the mode's
// purpose); the next sequence leaves when this one has ended.
void RunDelay(Soak& s) {
  constexpr Duration kDelay = std::chrono::milliseconds(300), kStep = std::chrono::milliseconds(50);
  while (s.Running()) {
    const int n = static_cast<int>(s.Uniform(3, 11));
    const bool paced = s.Uniform(0, 1) < 0.5;
    const TimePoint base = s.client.ServerNow() + kDelay;
    std::vector<Command> batch;
    for (int i = 0; i < n; ++i) {
      Command c = s.RandomCommand();
      c.start_time = StartTime::At(base + i * kStep);
      batch.push_back(std::move(c));
    }
    std::vector<PendingReply> pending;
    std::vector<std::size_t> index;  // pending[k] is batch[index[k]]
    try {
      if (paced) {
        const TimePoint t0 = Soak::SteadyNow();
        for (std::size_t i = 0; i < batch.size(); ++i) {
          std::this_thread::sleep_until(std::chrono::steady_clock::time_point(
              std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                  (t0 + static_cast<int>(i) * kStep).time_since_epoch())));
          pending.push_back(s.client.Send(batch[i]));
          index.push_back(i);
          s.Sent(pending.back().id(), batch[i], ToWireMicros(*batch[i].start_time.time()));
        }
      } else {
        pending = s.client.SendBatch(batch);
        for (std::size_t i = 0; i < batch.size(); ++i) {
          index.push_back(i);
          s.Sent(pending[i].id(), batch[i], ToWireMicros(*batch[i].start_time.time()));
        }
      }
    } catch (const Error& e) {
      s.NotSent("delay sequence of " + std::to_string(n) + ", " + std::to_string(pending.size()) + " sent",
                e.what());
      s.Sleep(0.2);
    }
    for (std::size_t k = 0; k < pending.size(); ++k) {
      const Duration until = *batch[index[k]].start_time.time() - s.client.ServerNow();
      s.Collect(pending[k], s.WaitFor(std::max(Duration(0), until)));
    }
    s.AfterPanic();
  }
}

// A marker query: its id bounds the ids a sequence used (ids come from one
// counter). Its reply is not awaited.
void Mark(Soak& s) {
  try {
    PendingReply p = s.client.SendQuery(Query{.type = QueryType::kBasePose});
    s.max_id = std::max(s.max_id, p.id());
    s.report.Line({{"ev", "marker"}, {"id", p.id()}});
  } catch (const Error& e) {
    s.NotSent("marker", e.what());
  }
}

// COMMAND_STATUS of ids (first, last): "kind" not_ended means the server
// still holds the command, unanswered; not_received that this session never
// got it; ended that "outcome" is its final reply's signal.
void AskStatus(Soak& s, CommandId first, CommandId last) {
  for (CommandId id = first; id < last; ++id) {
    std::string outcome, msg, kind = "failed";
    try {
      const Reply r = s.client.CommandStatus(id);
      outcome = ToString(r.signal);
      msg = r.message;
      const CommandStatusKind k = CommandStatusOf(r, id);
      kind = k == CommandStatusKind::kNotEnded      ? "not_ended"
             : k == CommandStatusKind::kNotReceived ? "not_received"
                                                    : "ended";
    } catch (const Error& e) {
      outcome = "STATUS_FAILED";
      msg = e.what();
    }
    s.report.Line({{"ev", "status"}, {"id", id}, {"outcome", outcome}, {"kind", kind}, {"msg", Short(msg)}});
  }
}

// Playback mode: sequences of 4..10 frames 100 ms apart; the server chooses
// the delay. A sequence that throws leaves its frames' ids unknown: the
// report names the id range (above `after`, below the next marker).
void RunPlayback(Soak& s) {
  while (s.Running()) {
    const int n = static_cast<int>(s.Uniform(4, 11));
    std::vector<TimedCommand> frames;
    for (int i = 0; i < n; ++i) frames.push_back({i * std::chrono::milliseconds(100), s.RandomCommand()});
    const std::vector<TimedCommand> copy = frames;
    Mark(s);
    const CommandId after = s.max_id;
    s.report.Line({{"ev", "seq"}, {"after", after}, {"frames", n}});
    try {
      const SequenceResult r = s.client.RunSequence(std::move(frames), {.mode = CommandMode::kPlayback});
      for (int i = 0; i < n; ++i) {
        const Reply& reply = r.replies[static_cast<std::size_t>(i)];
        const std::int64_t start =
            r.server_start ? ToWireMicros(*r.server_start + copy[static_cast<std::size_t>(i)].offset) : -1;
        s.Sent(reply.id, copy[static_cast<std::size_t>(i)].command, start);
        s.Final(reply.id, std::string(ToString(reply.signal)), reply.message, &reply);
      }
      s.AfterPanic();
    } catch (const Error& e) {
      const bool unknown = dynamic_cast<const UnknownOutcomeError*>(&e) != nullptr;
      const bool timeout = dynamic_cast<const TimeoutError*>(&e) != nullptr;
      s.report.Line({{"ev", "seq_failed"},
                     {"after", after},
                     {"frames", n},
                     {"outcome", unknown   ? "UNKNOWN_OUTCOME"
                                 : timeout ? "TIMEOUT"
                                           : "CLIENT_ERROR"},
                     {"msg", Short(e.what())}});
      s.Sleep(1.0);  // every frame's start has passed
      Mark(s);
      // A plain timeout leaves the session alive: ask what became of each
      // id of the sequence (its frames, and the PLAYBACK id itself).
      if (timeout && !unknown) AskStatus(s, after + 1, s.max_id);
      continue;
    }
    Mark(s);
  }
}

// Broadcast/watch: a STATE stream every 50 ms, asked again when it stops
// (a restarted server does not know the request), and a BASE_POSE each second.
void RunWatch(Soak& s) {
  // Shared with the callback, which the ReadDaemon may still be running when
  // this function returns.
  const auto counter = std::make_shared<std::atomic<long>>(0);
  std::atomic<long>& samples = *counter;
  long asked = 0, last = -1;
  while (s.Running()) {
    const long now = samples.load();
    if (now == last) {
      try {
        s.client.StartStateStream(std::chrono::milliseconds(50),
                                  [counter](const StateSample&) { ++*counter; });
        ++asked;
      } catch (const Error& e) {
        s.NotSent("STATE_STREAM", e.what());
      }
    }
    last = samples.load();
    try {
      s.client.BasePose();
    } catch (const Error& e) {
      s.NotSent("BASE_POSE", e.what());
    }
    s.Sleep(1.0);
  }
  s.report.Line({{"ev", "samples"}, {"n", samples.load()}, {"asked", asked}});
  try {
    s.client.StopStateStream();
  } catch (const Error&) {
  }
}

// Chaos: a panic every 2..6 s, reset 0.2..0.8 s later (seeded).
void RunChaos(Soak& s) {
  while (s.Running()) {
    s.Sleep(s.Uniform(2, 6));
    if (!s.Running()) break;
    std::string outcome = "ACKNOWLEDGED";
    try {
      s.client.Panic();
    } catch (const Error& e) {
      outcome = std::string("FAILED: ") + e.what();
    }
    s.report.Line({{"ev", "panic"}, {"outcome", outcome}});
    s.Sleep(s.Uniform(0.2, 0.8));
    for (int attempt = 0; attempt < 5; ++attempt) {  // a reset must not be left undone
      try {
        const Reply r = s.client.ResetPanic();
        s.report.Line({{"ev", "reset"}, {"outcome", ToString(r.signal)}});
        break;
      } catch (const Error& e) {
        s.report.Line({{"ev", "reset"}, {"outcome", "FAILED"}, {"msg", Short(e.what())}});
      }
    }
  }
}

int Main(int argc, char** argv) {
  const Args a(argc, argv, 1);
  const std::string mode = a.Str("mode", "direct");
  const long seed = a.Int("seed", 1);
  Report report(a.Str("out", "/dev/stdout"));
  ClientOptions o;
  o.lcm_url = a.Str("url", "");
  o.playback_copies = static_cast<int>(a.Int("playback-copies", kPlaybackCopiesAuto));
  RobotClient client(o);
  const TimePoint deadline = Soak::SteadyNow() + FromSeconds(a.Num("seconds", 10));
  // A client started while the server restarts retries until its deadline.
  for (int attempt = 0;; ++attempt) {
    try {
      client.Connect(a.Str("robot", "pioneer"));
      break;
    } catch (const Error& e) {
      if (Soak::SteadyNow() >= deadline || attempt >= 20) {
        std::fprintf(stderr, "robotalk-soak-client: cannot connect: %s\n", e.what());
        return 2;
      }
    }
  }
  report.Line({{"ev", "hello"},
               {"client", Hex64(static_cast<std::uint64_t>(client.client_id()))},
               {"mode", mode},
               {"seed", seed}});
  Soak s{client, report, std::mt19937_64(static_cast<std::uint64_t>(seed)), deadline};
  if (mode == "direct") {
    RunDirect(s);
  } else if (mode == "delay") {
    RunDelay(s);
  } else if (mode == "playback") {
    RunPlayback(s);
  } else if (mode == "watch") {
    RunWatch(s);
  } else if (mode == "chaos") {
    RunChaos(s);
  } else {
    std::fprintf(stderr, "robotalk-soak-client: unknown --mode '%s'\n", mode.c_str());
    return 2;
  }
  const ClientStats st = client.stats();
  report.Line({{"ev", "end"},
               {"retransmissions", st.retransmissions},
               {"gave_up", st.gave_up},
               {"sessions_opened", st.sessions_opened},
               {"sessions_lost", st.sessions_lost}});
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robotalk-soak-client: %s\n", e.what());
    return 2;
  }
}

// robotalk-bench-client: RoboTalk's side of the multi-process figures in
// docs/performance.md, through the public RobotClient API only.
//
//   robotalk-bench-client query    --url U --robot R --count N        BASE_POSE round trips (us)
//   robotalk-bench-client timed    --url U --robot R --count N [--period-us 1000 --lead-ms 100]
//                                  commands on a 1 kHz grid; the server's reported lateness (us)
//   robotalk-bench-client panic    --url U --robot R --count N [--gap-ms 20] [--state-period-us P]
//       Panic() ack (us), reset after; with P: also Panic() to the first STATE sample saying panic
//   each robotalk-bench-client pipe     --url U --robot R --inflight K --count M [--cap S]
//                                  single-command packages, K in flight; cmd/s, gave-ups
//   robotalk-bench-client stream   --url U --robot R --seconds T [--rate 100 --delay-ms 100 --start-at NS]
//                                  delay-mode stream (the scale client): timeouts, lateness, own CPU
//   robotalk-bench-client watch    --url U --robot R --count N [--period-us 1000]  STATE inter-arrival (us)
//   robotalk-bench-client playback --url U --robot R --frames N [--period-ms 100] [--copies 0|1|2] [--warmup
//   K]  the server's chosen delay (copies 0, the default: decided from the link; K sequences before,
//   unmeasured)
// Each prints one JSON line on stdout. Every loop is bounded in count and time.
#include "bench_util.h"
#include "robotalk/robot_client.h"

#include <sys/resource.h>

#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>

using namespace robotalk;
using namespace robotalk::bench;

namespace {

double Us(Duration d) { return static_cast<double>(d.count()) / 1e3; }

ClientOptions Options(const Args& a) {
  ClientOptions o;
  o.lcm_url = a.Str("url", "");
  return o;
}

Command Pan(int k, std::optional<TimePoint> start) {
  return Command{
      .type = CommandType::kJointSetPoint, .start_time = start, .target = "pan", .values = {0.05 * (k % 4)}};
}

std::vector<Field> StatsFields(const RobotClient& c) {
  const ClientStats s = c.stats();
  return {Field("retransmissions", static_cast<double>(s.retransmissions)),
          Field("gave_up", static_cast<double>(s.gave_up))};
}

double CpuSeconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return static_cast<double>(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
         static_cast<double>(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec) / 1e6;
}

int QueryRtt(const Args& a) {
  RobotClient c(Options(a));
  c.Connect(a.Str("robot", "pioneer"));
  const long count = a.Int("count", 1000), warmup = a.Int("warmup", 50);
  std::vector<double> rtt;
  for (long i = 0; i < count + warmup; ++i) {
    const std::int64_t t0 = MonoNs();
    c.BasePose();
    if (i >= warmup) rtt.push_back(static_cast<double>(MonoNs() - t0) / 1e3);
  }
  auto f = StatsFields(c);
  f.insert(f.begin(), Summary("rtt_us", rtt));
  PrintJson(f);
  return 0;
}

// Commands on a fixed server-clock grid, each sent --lead-ms before its start
// in packages of 10 (every 10 ms at 1 kHz): the server's timer is measured,
// not the network.
int Timed(const Args& a) {
  RobotClient c(Options(a));
  c.Connect(a.Str("robot", "pioneer"));
  const long count = a.Int("count", 2000);
  const Duration period = std::chrono::microseconds(a.Int("period-us", 1000));
  const Duration lead = std::chrono::milliseconds(a.Int("lead-ms", 100));
  const TimePoint base = c.ServerNow() + lead + std::chrono::milliseconds(50);
  std::vector<PendingReply> pending;
  for (long k = 0; k < count; k += 10) {
    const TimePoint first = base + k * period;
    std::this_thread::sleep_until(c.ClientTime(first - lead));
    std::vector<Command> batch;
    for (long j = k; j < std::min(count, k + 10); ++j)
      batch.push_back(Pan(static_cast<int>(j), base + j * period));
    for (auto& p : c.SendBatch(std::move(batch))) pending.push_back(std::move(p));
  }
  std::vector<double> late;
  long failed = 0, timeouts = 0;
  for (auto& p : pending) {
    try {
      const Reply r = p.Wait(std::chrono::seconds(6));
      if (!Succeeded(r.signal)) ++failed;
      late.push_back(Us(r.lateness));
    } catch (const TimeoutError&) {
      ++timeouts;
    }
  }
  auto f = StatsFields(c);
  f.insert(f.begin(), {Summary("lateness_us", late), Field("not_success", static_cast<double>(failed)),
                       Field("timeouts", static_cast<double>(timeouts))});
  PrintJson(f);
  return 0;
}

// With --state-period-us P > 0 it also watches the robot's STATE stream at
// that period and measures, per panic, the time from Panic() to the first
// sample that says panic (issue 11: "halt visible on a 1 kHz STATE stream").
int PanicAck(const Args& a) {
  RobotClient c(Options(a));
  c.Connect(a.Str("robot", "pioneer"));
  const long count = a.Int("count", 100);
  const long state_period_us = a.Int("state-period-us", 0);
  std::mutex mu;
  std::condition_variable seen_cv;
  std::int64_t panic_sent = 0, panic_seen = 0;  // GUARDED_BY(mu); 0 = none pending / none yet
  if (state_period_us > 0) {
    c.StartStateStream(std::chrono::microseconds(state_period_us), [&](const StateSample& s) {
      const std::int64_t now = MonoNs();
      std::lock_guard<std::mutex> lock(mu);
      if (s.panic && panic_sent != 0 && panic_seen == 0) {
        panic_seen = now;
        seen_cv.notify_all();
      }
    });
    SleepUntilNs(MonoNs() + 200000000);  // the stream is running
  }
  std::vector<double> ack, visible;
  long timeouts = 0, never_visible = 0;
  for (long i = 0; i < count; ++i) {
    SleepUntilNs(MonoNs() + a.Int("gap-ms", 20) * 1000000);
    const std::int64_t t0 = MonoNs();
    {
      std::lock_guard<std::mutex> lock(mu);
      panic_sent = t0;
      panic_seen = 0;
    }
    try {
      c.Panic();
      ack.push_back(static_cast<double>(MonoNs() - t0) / 1e3);
    } catch (const TimeoutError&) {
      ++timeouts;
    }
    if (state_period_us > 0) {
      std::unique_lock<std::mutex> lock(mu);
      if (seen_cv.wait_for(lock, std::chrono::seconds(1), [&] { return panic_seen != 0; })) {
        visible.push_back(static_cast<double>(panic_seen - t0) / 1e3);
      } else {
        ++never_visible;
      }
      panic_sent = 0;
    }
    c.ResetPanic();
  }
  if (state_period_us > 0) c.StopStateStream();
  auto f = StatsFields(c);
  f.insert(f.begin(), {Summary("ack_us", ack), Field("timeouts", static_cast<double>(timeouts))});
  if (state_period_us > 0) {
    f.insert(f.begin() + 2, {Summary("halt_visible_us", visible),
                             Field("halt_never_visible", static_cast<double>(never_visible))});
  }
  PrintJson(f);
  return 0;
}

enum class Outcome { kReady, kPending, kLost };

// Waits at most `wait` for `p`. A TimeoutError from Wait() is either the wait
// itself or the client giving up on the package; Poll() tells them apart (a
// given-up id has been consumed, so Poll throws).
// Polls first, so the normal path (the reply is there, or a zero wait finds
// it not yet there) throws nothing: a TimeoutError per not-yet-answered
// command was 9 % of a loaded scale client's CPU in exception unwinding.
Outcome WaitFor(PendingReply& p, Duration wait, Reply* out) {
  if (wait.count() > 0) {
    try {
      if (auto r = p.Poll()) {
        *out = *r;
        return Outcome::kReady;
      }
      *out = p.Wait(wait);
      return Outcome::kReady;
    } catch (const TimeoutError&) {
    } catch (const Error&) {
      return Outcome::kLost;
    }
  }
  try {
    if (auto r = p.Poll()) {
      *out = *r;
      return Outcome::kReady;
    }
    return Outcome::kPending;
  } catch (const Error&) {
    return Outcome::kLost;
  }
}

// One Send() per command (one package each), --inflight of them outstanding.
int Pipe(const Args& a) {
  RobotClient c(Options(a));
  c.Connect(a.Str("robot", "pioneer"));
  const long inflight = a.Int("inflight", 100), count = a.Int("count", 20000);
  const std::int64_t t0 = MonoNs(), cap = t0 + static_cast<std::int64_t>(a.Num("cap", 60) * 1e9);
  std::deque<PendingReply> window;
  long sent = 0, done = 0, lost = 0, failed = 0;
  while (done < count && MonoNs() < cap) {
    while (sent < count && static_cast<long>(window.size()) < inflight) {
      window.push_back(c.Send(Pan(static_cast<int>(sent), std::nullopt)));
      ++sent;
    }
    Reply r;
    const Outcome o = WaitFor(window.front(), std::chrono::milliseconds(100), &r);
    if (o == Outcome::kPending) continue;
    if (o == Outcome::kLost) ++lost;
    if (o == Outcome::kReady && !Succeeded(r.signal)) ++failed;
    window.pop_front();
    ++done;
  }
  const double secs = static_cast<double>(MonoNs() - t0) / 1e9;
  auto f = StatsFields(c);
  f.insert(f.begin(),
           {Field("per_s", static_cast<double>(done - lost) / secs), Field("done", static_cast<double>(done)),
            Field("seconds", secs), Field("timed_out", done < count ? 1 : 0),
            Field("lost", static_cast<double>(lost)), Field("not_success", static_cast<double>(failed))});
  PrintJson(f);
  std::_Exit(0);  // a collapsed run leaves a window behind: do not wait for it
}

// The scale client: one command every 1/rate s, stamped server now + delay.
int Stream(const Args& a) {
  RobotClient c(Options(a));
  const double cpu0 = CpuSeconds();
  try {
    c.Connect(a.Str("robot", "pioneer"));
  } catch (const Error& e) {
    PrintJson({Field("connect_failed", 1)});
    std::_Exit(0);
  }
  if (a.Int("start-at", 0) > MonoNs()) SleepUntilNs(a.Int("start-at", 0));
  const double cpu1 = CpuSeconds();
  const std::int64_t t0 = MonoNs(), period = static_cast<std::int64_t>(1e9 / a.Num("rate", 100));
  const auto n = static_cast<long>(a.Num("seconds", 5) * a.Num("rate", 100));
  const Duration delay = std::chrono::milliseconds(a.Int("delay-ms", 100));
  std::deque<PendingReply> pending;
  std::vector<double> late;
  long lost = 0, failed = 0, panicked = 0;
  auto collect = [&](Duration wait) {
    Reply r;
    const Outcome o = WaitFor(pending.front(), wait, &r);
    if (o == Outcome::kPending) return false;
    if (o == Outcome::kLost) ++lost;
    if (o == Outcome::kReady) {
      if (r.signal == Signal::kPanic || r.signal == Signal::kInterrupted) {
        ++panicked;
      } else {
        if (!Succeeded(r.signal)) ++failed;
        late.push_back(Us(r.lateness));
      }
    }
    pending.pop_front();
    return true;
  };
  for (long k = 0; k < n; ++k) {
    SleepUntilNs(t0 + k * period);
    pending.push_back(c.Send(Pan(static_cast<int>(k), c.ServerNow() + delay)));
    while (!pending.empty() && collect(Duration(0))) {
    }
  }
  const std::int64_t stream_end = MonoNs();
  const double cpu2 = CpuSeconds();
  const std::int64_t bound = MonoNs() + 7000000000;  // past the client's 5 s give-up
  while (!pending.empty() && MonoNs() < bound) collect(std::chrono::milliseconds(100));
  const double wall = static_cast<double>(stream_end - t0) / 1e9;
  auto f = StatsFields(c);
  f.insert(f.begin(),
           {Summary("lateness_us", late), Field("sent", static_cast<double>(n)),
            Field("timeouts", static_cast<double>(lost + static_cast<long>(pending.size()))),
            Field("not_success", static_cast<double>(failed)),
            Field("panicked", static_cast<double>(panicked)), Field("cpu_pct", 100 * (cpu2 - cpu1) / wall),
            Field("connect_cpu_s", cpu1 - cpu0), Field("connect_failed", 0)});
  PrintJson(f);
  std::_Exit(0);
}

// STATE samples as the client's callback sees them.
int Watch(const Args& a) {
  RobotClient c(Options(a));
  c.Connect(a.Str("robot", "pioneer"));
  const long count = a.Int("count", 2000);
  const double period_us = a.Num("period-us", 1000);
  std::mutex mu;
  std::vector<std::int64_t> arrivals;
  arrivals.reserve(static_cast<std::size_t>(count) + 16);
  c.StartStateStream(std::chrono::microseconds(static_cast<long>(period_us)),
                     [&](const auto&) {  // robot_state_t or the C++ state type: either API
                       std::lock_guard<std::mutex> lock(mu);
                       if (static_cast<long>(arrivals.size()) < count + 16) arrivals.push_back(MonoNs());
                     });
  const std::int64_t end = MonoNs() + static_cast<std::int64_t>(a.Num("timeout", 30) * 1e9);
  for (;;) {
    {
      std::lock_guard<std::mutex> lock(mu);
      if (static_cast<long>(arrivals.size()) >= count + 16 || MonoNs() > end) break;
    }
    SleepUntilNs(MonoNs() + 20000000);
  }
  c.StopStateStream();
  std::lock_guard<std::mutex> lock(mu);
  std::vector<double> gap, dev;
  for (std::size_t i = 17; i < arrivals.size(); ++i) {  // the first samples follow the request
    gap.push_back(static_cast<double>(arrivals[i] - arrivals[i - 1]) / 1e3);
    dev.push_back(std::abs(gap.back() - period_us));
  }
  PrintJson({Summary("interarrival_us", gap), Summary("deviation_us", dev),
             Field("received", static_cast<double>(arrivals.size()))});
  return 0;
}

// A paced playback sequence; the server's chosen delay (after its first frame
// arrived) and how late the frames ran.
int Playback(const Args& a) {
  ClientOptions o = Options(a);
  o.timeout = std::chrono::seconds(30);
  o.connect_timeout = std::chrono::seconds(20);
  // playback redundancy: 1 off, 2 always, 0 (the library's default) decided from the link
  o.playback_copies = static_cast<int>(a.Int("copies", ClientOptions{}.playback_copies));
  RobotClient c(o);
  c.Connect(a.Str("robot", "pioneer"));
  const long frames = a.Int("frames", 40);
  const Duration period = std::chrono::milliseconds(a.Int("period-ms", 100));
  std::vector<TimedCommand> seq;
  for (long k = 0; k < frames; ++k) seq.push_back({k * period, Pan(static_cast<int>(k), std::nullopt)});
  SequenceOptions so;
  so.mode = CommandMode::kPlayback;
  so.paced = true;
  // --warmup K: K unmeasured sequences first, in the same session (a
  // long-lived client, whose link figures have had time to form).
  for (long k = a.Int("warmup", 0); k > 0; --k) c.RunSequence(seq, so);
  const ClientStats before = c.stats();
  const SequenceResult r = c.RunSequence(std::move(seq), so);
  std::vector<double> late;
  long late_frames = 0, not_run = 0, over_bound = 0, over_default = 0;
  // The timing as played (issue 23): each gap between successive frames'
  // execution times against the recorded 'period'; a gap longer than the
  // server's stretch bound (+ 1 ms of the RobotDaemon's wake-up) is a pause
  // for a late frame.
  const double bound = a.Num("stretch-bound", 0.10);
  double max_stretch = 0;
  std::optional<TimePoint> previous;
  Json late_detail = Json::array();  // each late frame: [its index, lateness ms, the gap before it ms]
  for (const Reply& rep : r.replies) {
    late.push_back(Us(rep.lateness));
    if (rep.lateness > std::chrono::milliseconds(1)) {
      ++late_frames;
      late_detail.push_back({static_cast<double>(late.size() - 1), ToSeconds(rep.lateness) * 1e3,
                             previous ? ToSeconds(rep.exec_time - *previous) * 1e3 : 0.0});
    }
    if (rep.signal != Signal::kSuccess && rep.signal != Signal::kModified) {
      ++not_run;
      previous.reset();
      continue;
    }
    if (previous) {
      const double gap = ToSeconds(rep.exec_time - *previous), recorded = ToSeconds(period);
      max_stretch = std::max(max_stretch, gap / recorded - 1);
      if (gap > recorded * (1 + bound) + 0.001) ++over_bound;
      if (gap > recorded * 1.10 + 0.001)
        ++over_default;  // past the normal 10 % (a thin buffer's, or a pause)
    }
    previous = rep.exec_time;
  }
  const double total_stretch = r.replies.size() >= 2
                                   ? ToSeconds(r.replies.back().exec_time - r.replies.front().exec_time) -
                                         ToSeconds(period) * static_cast<double>(r.replies.size() - 1)
                                   : 0;
  auto f = StatsFields(c);
  const ClientStats stats = c.stats();
  f.insert(
      f.begin(),
      {Field("chosen_delay_s", r.playback_delay ? ToSeconds(*r.playback_delay) : -1),
       Field("copies_option", static_cast<double>(o.playback_copies)),
       Field("playback_copies", static_cast<double>(stats.playback_copies - before.playback_copies)),
       Field("messages_lost", static_cast<double>(stats.messages_lost)),
       Field("messages_lost_before", static_cast<double>(before.messages_lost)), Summary("lateness_us", late),
       Field("late_frames", static_cast<double>(late_frames)), Field("not_run", static_cast<double>(not_run)),
       Field("gaps_over_bound", static_cast<double>(over_bound)),
       Field("gaps_over_10pct", static_cast<double>(over_default)), Field("late_detail", late_detail),
       Field("max_gap_stretch", max_stretch), Field("total_stretch_s", total_stretch)});
  PrintJson(f);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s query|timed|panic|pipe|stream|watch|playback [--key value ...]\n",
                 argv[0]);
    return 2;
  }
  try {
    const std::string cmd = argv[1];
    const Args a(argc, argv, 2);
    if (cmd == "query") return QueryRtt(a);
    if (cmd == "timed") return Timed(a);
    if (cmd == "panic") return PanicAck(a);
    if (cmd == "pipe") return Pipe(a);
    if (cmd == "stream") return Stream(a);
    if (cmd == "watch") return Watch(a);
    if (cmd == "playback") return Playback(a);
    std::fprintf(stderr, "robotalk-bench-client: unknown sub-command '%s'\n", cmd.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robotalk-bench-client: %s\n", e.what());
    return 1;
  }
}

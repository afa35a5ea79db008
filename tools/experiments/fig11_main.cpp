// robotalk-fig11: one run of the paper's Fig. 11 experiment (§VI-B).
//
// Connects to a robot, records its base trajectory from the broadcast STATE
// stream, sends the Fig. 11 SETSPEED profile (fig11_profile.h) in one command
// mode with frames paced every frame period (RobotClient::RunSequence,
// paced = true), and writes the trajectory and metrics against the ideal
// path. See docs/experiment.md.
//
//   robotalk-fig11 --url URL --mode direct|delay|playback [--delay S]
//                  [--length M] [--duration S] --out PREFIX [--label L]
//   robotalk-fig11 --print-ideal FILE [--length M] [--duration S]
//
// Exit status: 0 success; 1 the run failed (timeout, refused frames);
// 2 usage; 3 the run exceeded --max-seconds.
#include "fig11_profile.h"
#include "robotalk/log_writer.h"  // OpenStandardDescriptors
#include "robotalk/option_reader.h"
#include "robotalk/robot_client.h"
#include "robotalk/sequence_file.h"  // ParseNumberIn

#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace {

using namespace robotalk;
using namespace robotalk::experiments;

constexpr const char* kUsage = R"(usage: robotalk-fig11 [options]
One run of the paper's Fig. 11 experiment (docs/experiment.md).
  --url URL               LCM URL (default: LCM's default)
  --robot NAME            robot name (default pioneer)
  --mode M                direct | delay | playback (default direct)
  --delay S               delay mode's delay budget in seconds (default 10)
  --length M              path length in metres (default 6)
  --duration S            profile duration in seconds, rounded to a multiple of 0.8 (default 30)
  --state-period S        STATE stream period (default 0.02)
  --out PREFIX            write PREFIX_traj.csv and PREFIX_metrics.csv
  --label TEXT            condition label written in the metrics (default "")
  --congestion TEXT       congestion description written in the metrics (default "none")
  --retransmit-interval S first resend of an unacknowledged package (default 0.1, the client's default)
  --give-up S             client gives up on a silent package after S (default 5)
  --max-seconds S         hard bound on the whole run (default 300): exit 3 past it
  --max-late S|never|default
                          the frames' deadline (ClientOptions::max_late; default: the
                          robot's --max-late). Expired frames are counted, not failures
  --print-ideal FILE      write the ideal path (t x y theta every 0.02 s) and exit
  --version               print the version and exit
  -h, --help              print this help and exit
)";

struct Options {
  std::string url, robot = "pioneer", out, label, congestion = "none", print_ideal;
  CommandMode mode = CommandMode::kDirect;
  double delay = 10, length = 6, duration = 30, state_period = 0.02;
  double retransmit_interval = 0.1, give_up = 5, max_seconds = 300;
  Duration max_late = kMaxLateServerDefault;
};

Options Parse(int argc, char** argv) {
  Options o;
  OptionReader r(argc, argv);
  while (r.Next()) {
    const std::string& a = r.word();
    if (r.IsHelp()) {
      std::cout << kUsage;
      std::exit(0);
    } else if (r.IsVersion()) {
      std::cout << "robotalk-fig11 " << ROBOTALK_VERSION << "\n";
      std::exit(0);
    } else if (a == "--url") {
      o.url = r.Value();
    } else if (a == "--robot") {
      o.robot = r.Value();
    } else if (a == "--mode") {
      const std::string m = r.Value();
      auto mode = ParseCommandMode(m);
      if (!mode) throw std::invalid_argument("--mode: '" + m + "' is not direct, delay or playback");
      o.mode = *mode;
    } else if (a == "--delay") {
      o.delay = ParseNumberIn(r.Value(), a, {0, 3600});
    } else if (a == "--length") {
      o.length = ParseNumberIn(r.Value(), a, {0.01, 1000});
    } else if (a == "--duration") {
      o.duration = ParseNumberIn(r.Value(), a, {0.8, 3600});
    } else if (a == "--state-period") {
      o.state_period = ParseNumberIn(r.Value(), a, {0.001, 1});
    } else if (a == "--out") {
      o.out = r.Value();
    } else if (a == "--label") {
      o.label = r.Value();
    } else if (a == "--congestion") {
      o.congestion = r.Value();
    } else if (a == "--retransmit-interval") {
      o.retransmit_interval = ParseNumberIn(r.Value(), a, {0.001, 3600});
    } else if (a == "--give-up") {
      o.give_up = ParseNumberIn(r.Value(), a, {0.1, 3600});
    } else if (a == "--max-seconds") {
      o.max_seconds = ParseNumberIn(r.Value(), a, {1, 86400});
    } else if (a == "--max-late") {
      const std::string v = r.Value();
      o.max_late = v == "never"     ? kMaxLateNever
                   : v == "default" ? kMaxLateServerDefault
                                    : FromSeconds(ParseNumberIn(v, a, {1e-6, 3600}));
    } else if (a == "--print-ideal") {
      o.print_ideal = r.Value();
    } else {
      r.Unknown();
    }
  }
  if (o.print_ideal.empty() && o.out.empty()) throw std::invalid_argument("--out PREFIX is required");
  return o;
}

struct Sample {
  TimePoint t;
  Pose2 pose;
};

// The trajectory recorder: STATE samples arrive on the client's ReadDaemon.
class Recorder {
 public:
  void Add(const StateSample& s) {
    std::lock_guard lock(mu_);
    samples_.push_back({s.server_time, {s.base.x, s.base.y, s.base.theta}});
    cv_.notify_all();
  }
  // Waits (bounded) until a sample at or after server time `t` has arrived.
  bool WaitFor(TimePoint t, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mu_);
    return cv_.wait_for(lock, timeout, [&] { return !samples_.empty() && samples_.back().t >= t; });
  }
  bool WaitCount(std::size_t n, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mu_);
    return cv_.wait_for(lock, timeout, [&] { return samples_.size() >= n; });
  }
  std::vector<Sample> Take() {
    std::lock_guard lock(mu_);
    std::vector<Sample> out = samples_;
    std::sort(out.begin(), out.end(), [](const Sample& a, const Sample& b) { return a.t < b.t; });
    return out;
  }

 private:
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<Sample> samples_;
};

void WriteIdeal(const std::string& file, const Fig11Profile& profile) {
  const IdealPath path(profile, {});
  std::ofstream f(file);
  f << "t,x,y,theta\n";
  const int steps = static_cast<int>(std::lround(profile.duration / 0.02));
  char line[128];
  for (int i = 0; i <= steps; ++i) {
    const double t = i * 0.02;
    const Pose2 p = path.At(t);
    std::snprintf(line, sizeof line, "%.3f,%.6f,%.6f,%.6f\n", t, p.x, p.y, p.theta);
    f << line;
  }
  if (!f) throw std::runtime_error("cannot write " + file);
}

int Run(const Options& o) {
  const Fig11Profile profile = MakeFig11Profile({.length = o.length, .duration = o.duration});
  if (!o.print_ideal.empty()) {
    WriteIdeal(o.print_ideal, profile);
    std::printf("ideal path: r = %.4f m, v = %.4f m/s, %d frames per small half circle, %.1f s, %zu frames\n",
                profile.radius, profile.speed, profile.frames_per_small, profile.duration,
                profile.frames.size());
    return 0;
  }

  ClientOptions co;
  co.lcm_url = o.url;
  co.timeout = std::chrono::seconds(120);
  co.connect_timeout = std::chrono::seconds(30);
  co.retransmit_interval = FromSeconds(o.retransmit_interval);
  co.retransmit_max_interval = std::max(co.retransmit_max_interval, co.retransmit_interval);
  co.give_up_after = FromSeconds(o.give_up);
  co.max_late = o.max_late;
  RobotClient client(co);
  client.Connect(o.robot);

  Recorder recorder;
  client.StartStateStream(FromSeconds(o.state_period), [&](const StateSample& s) { recorder.Add(s); });
  if (!recorder.WaitCount(3, std::chrono::seconds(20)))
    throw std::runtime_error("no STATE samples within 20 s");

  std::vector<TimedCommand> frames;
  for (const SpeedFrame& f : profile.frames) {
    frames.push_back(
        {FromSeconds(f.offset), Command{.type = CommandType::kSetSpeed, .values = {f.v, f.omega}}});
  }
  const Pose2 start = recorder.Take().back().pose;
  SequenceOptions so{.mode = o.mode, .delay = FromSeconds(o.delay), .paced = true};
  std::fprintf(stderr, "robotalk-fig11: %s%s, %zu frames over %.1f s, start (%.3f, %.3f, %.3f)\n",
               ToString(o.mode),
               o.mode == CommandMode::kDelay ? (" " + std::to_string(o.delay) + " s").c_str() : "",
               frames.size(), profile.duration, start.x, start.y, start.theta);
  const SequenceResult result = client.RunSequence(std::move(frames), so);

  const TimePoint sent0 = client.ServerTime(result.first_sent);
  const TimePoint exec0 = result.replies.front().exec_time;
  const TimePoint exec_last = result.replies.back().exec_time;
  // The last samples after the stop frame (published late under congestion).
  recorder.WaitFor(exec_last + std::chrono::milliseconds(300), std::chrono::seconds(30));
  client.StopStateStream();
  const std::vector<Sample> samples = recorder.Take();

  // Metrics (docs/experiment.md, "Metrics").
  const IdealPath ideal(profile, start);
  std::vector<Pose2> moving;
  std::optional<Pose2> final_pose;
  for (const Sample& s : samples) {
    if (s.t >= exec0 && s.t <= exec_last) moving.push_back(s.pose);
    if (s.t >= exec_last) final_pose = s.pose;
  }
  if (!final_pose) {
    const Reply r = client.BasePose();
    if (r.values.size() >= 3) final_pose = Pose2{r.values[0], r.values[1], r.values[2]};
  }
  moving.push_back(*final_pose);
  const Deviation dev = MeasureDeviation(ideal, moving);
  const Pose2 ideal_end = ideal.End();
  const double end_error = std::hypot(final_pose->x - ideal_end.x, final_pose->y - ideal_end.y);
  const double start_latency = ToSeconds(exec0 - sent0);
  double max_sched = 0, max_late = 0;
  int late = 0, not_ok = 0, expired = 0;
  std::ofstream per_frame(o.out + "_frames.csv");  // each frame's fate (the stall figure)
  per_frame << "offset_s,signal,exec_s,lateness_s\n";
  for (std::size_t i = 0; i < result.replies.size(); ++i) {
    const Reply& r = result.replies[i];
    const bool ran = Succeeded(r.signal);
    if (r.signal == Signal::kInterrupted && r.message.starts_with("expired:")) ++expired;
    char row[128];
    std::snprintf(row, sizeof row, "%.3f,%s,%.4f,%.4f\n", profile.frames[i].offset,
                  std::string(ToString(r.signal)).c_str(), ran ? ToSeconds(r.exec_time - sent0) : -1.0,
                  ToSeconds(r.lateness));
    per_frame << row;
    if (!ran) {
      ++not_ok;
      continue;  // a frame that did not run has no schedule error
    }
    const double sched = ToSeconds(r.exec_time - exec0) - profile.frames[i].offset;
    max_sched = std::max(max_sched, std::abs(sched));
    max_late = std::max(max_late, ToSeconds(r.lateness));
    if (r.lateness > std::chrono::milliseconds(5)) ++late;
  }
  const double playback_delay = result.playback_delay ? ToSeconds(*result.playback_delay) : 0.0;

  std::ofstream traj(o.out + "_traj.csv");
  traj << "t,x,y,theta\n";
  char line[256];
  for (const Sample& s : samples) {
    std::snprintf(line, sizeof line, "%.4f,%.6f,%.6f,%.6f\n", ToSeconds(s.t - sent0), s.pose.x, s.pose.y,
                  s.pose.theta);
    traj << line;
  }
  if (!traj) throw std::runtime_error("cannot write " + o.out + "_traj.csv");

  std::ofstream metrics(o.out + "_metrics.csv");
  metrics << "label,congestion,mode,delay_s,frames,profile_s,start_latency_s,playback_delay_s,actual_s,"
             "max_schedule_error_s,late_frames,max_lateness_s,not_success,samples,mean_dev_m,max_dev_m,end_"
             "error_m,expired_frames\n";
  std::snprintf(
      line, sizeof line, "%s,%s,%s,%.3f,%zu,%.1f,%.3f,%.3f,%.3f,%.4f,%d,%.3f,%d,%zu,%.5f,%.5f,%.5f,%d\n",
      o.label.c_str(), o.congestion.c_str(), ToString(o.mode), o.mode == CommandMode::kDelay ? o.delay : 0.0,
      profile.frames.size(), profile.duration, start_latency, playback_delay, ToSeconds(exec_last - exec0),
      max_sched, late, max_late, not_ok, dev.samples, dev.mean, dev.max, end_error, expired);
  metrics << line;
  if (!metrics) throw std::runtime_error("cannot write " + o.out + "_metrics.csv");
  std::printf(
      "%s %s: start latency %.3f s, playback delay %.3f s, ran %.2f s (profile %.1f s), schedule error max "
      "%.4f s, "
      "late %d (max %.3f s), not-success %d, deviation mean %.4f m max %.4f m, end error %.4f m (%zu "
      "samples)\n",
      o.label.c_str(), ToString(o.mode), start_latency, playback_delay, ToSeconds(exec_last - exec0),
      profile.duration, max_sched, late, max_late, not_ok, dev.mean, dev.max, end_error, dev.samples);
  const ClientStats st = client.stats();
  std::fprintf(
      stderr,
      "robotalk-fig11: client sent %llu packages (%llu heartbeats, %llu retransmissions, %llu given up)\n",
      static_cast<unsigned long long>(st.packages_sent), static_cast<unsigned long long>(st.heartbeats),
      static_cast<unsigned long long>(st.retransmissions), static_cast<unsigned long long>(st.gave_up));
  // Frames refused by their deadline are the experiment's point, not a failure.
  return not_ok - expired == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  robotalk::OpenStandardDescriptors();  // first: nothing of ours on descriptors 0-2
  Options o;
  try {
    o = Parse(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robotalk-fig11: %s\n%s", e.what(), kUsage);
    return 2;
  }
  // A hard bound on the run, whatever happens on the network.
  std::thread([limit = o.max_seconds] {
    std::this_thread::sleep_for(std::chrono::duration<double>(limit));
    std::fprintf(stderr, "robotalk-fig11: run exceeded --max-seconds %.0f; giving up\n", limit);
    std::fflush(stderr);
    _exit(3);
  }).detach();
  try {
    return Run(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robotalk-fig11: %s\n", e.what());
    return 1;
  }
}

// The walking humanoid's phase sweep (issue 26, item 2; not a test): for each
// transition — a command that cuts into a running walk and a command that
// restarts it — the cutting command is sent at every `--every` ms over
// `--span` s of the gait (from `--from` s after the first command), each run
// from a fresh driver, and the run counts as a fall when the torso tilts past
// the driver's bound within `--after` s of the last command. Prints per
// transition the runs, falls and the worst tilt, and the instants that fell.
// models/simple_humanoid.urdf on the ode driver (walk=true) at 1 kHz.
//   robotalk-walk-sweep [--transition NAME|all] [--from S] [--span S] [--every MS]
//                       [--after S] [--model URDF] [--option key=value]...
// (--model: another humanoid, e.g. ../shared/robots/atlas.urdf --option base=floating.)
// The phase sweep runs the driver's defaults (the stabilizer on since the
// fourteenth session; --option stabilizer=false for the open loop); --push, --probe, --rtf and --arms set the
// stabilizer per --stabilizer (on: true, off: false, both: each), whatever
// the driver's default.
//   robotalk-walk-sweep --push standing|walking|all [--stabilizer on|off|both]
//     [--resolution N_S] [--seed S]: per direction (8, every 45 degrees, 0 = a
//     push forward, counter-clockwise) the largest impulse on the pelvis
//     survived (a 0.1 s push through OdeDriver::PushForTesting, found by
//     bisection in [0, 80] N s to --resolution, default 2.5), standing and/or
//     walking at the gait's full forward speed (the push lands at a seeded
//     instant of the gait cycle, the same per direction for every column),
//     with and/or without the balance feedback (option stabilizer), in one
//     table, then the arm swing below for the same stabilizer settings.
//   robotalk-walk-sweep --push walking --instants K [--levels 10,15,20,25,30,40]
//     [--cycle S] [--seed S]: a steadier measure than one instant's bisection
//     (survival is not monotonic in the impulse, and one ulp of direction or
//     1 ms of instant flips a result there): K push instants stratified over
//     --cycle s of the gait (default 1.52, two steps of the derived gait) from
//     5 s into the walk, jittered by --seed, the same for every direction; per
//     direction and impulse level, the fraction of the K instants survived,
//     and the median over the instants of the largest level survived below the
//     first level that fell. Each instant's walk is run once up to the push and
//     forked per (direction, level): the child is that run continued (the
//     driver is deterministic and single-threaded), so 8 x K x levels pushes
//     cost K walks of ~6.5 s plus 8 x K x levels x <= --after s simulated.
//     --nudge 1: every push direction one ulp larger: the same sweep but for a
//     difference no controller makes, i.e. how far chaos alone moves the figures
//     (measured: not at all, 0 of 384 pushes changed). --shift S: every instant
//     S s later (the run steps in 10 ms, so 0.01 moves each push by one step of
//     the loop): how far a small change of phase moves them.
//   robotalk-walk-sweep --push goto[,DEG,N_S] [--stabilizer on|off|both]: the pushed
//     GOTO: a 1.5 m GOTO after 1 s standing, a 0.1 s push on the pelvis (DEG,N_S;
//     default both sides, 90 and 270 at 8 N s) at 21 instants 2.50-3.50 s after
//     the command (every 50 ms), each a fresh driver with the walking tests'
//     seed 7 and their first 1 ms step (so the 3.00 s instant is
//     OdeWalk.APushedGotoStopsStandsThenReplansAndStillArrives), run until the
//     GOTO answers, the walker falls or 60 s pass. Prints per direction and
//     setting the pattern by instant (F fell, . arrived: SUCCESS within 5 cm of
//     the goal, s no answer in 60 s, x answered otherwise), the counts, each
//     fall's time after its push, and with both settings McNemar's z.
//     goto,DEG,N_S,AT: the one instant AT s after the command (--trace F as --probe's).
//   robotalk-walk-sweep --probe standing|walking,DEG,N_S[,AT] [--trace F]: one push (at AT s
//     after the start of the walk, default 5.5; standing 2); survived or not; --trace
//     writes F.on.csv / F.off.csv (scripts/plot_walk_push.py plots them), a row every
//     10 ms (--trace-ms MS: every MS ms).
//   robotalk-walk-sweep --rtf S [--stabilizer ...]: CPU per physics step walking S s.
//   robotalk-walk-sweep --arms 1 [--stabilizer ...]: both shoulders swung
//     together +-1 rad every 0.5 s for 6 s, standing and walking: fell or not.
// Transitions (t = the swept instant, s after the first command):
//   stop_goto        GOTO 1 m; STOP at t; GOTO 1 m at t + 0.1 s
//   stop_wait_goto   GOTO 1 m; STOP at t; GOTO 1 m at t + 1.2 s
//   speed_zero_back  SETSPEED full; SETSPEED 0 at t; SETSPEED full at t + 1 s (full:
//                    1 m/s, clamped to the gait's forward limit)
//   panic_reset_goto GOTO 1 m; panic (Halt) at t, reset; GOTO 1 m at t + 0.1 s
//   stop             GOTO 1 m; STOP at t (the first shift of weight, a step, ...)
// docs/ode_sim.md ("Walking", "Replanning") has the table.
#include "ode_driver.h"
#include "walk_bench_util.h"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <vector>

using namespace robotalk;

namespace {

struct Args {
  std::string model = bench::DefaultWalkModel();
  std::string transition = "all";
  double from = 1.0, span = 2.0, after = 4.0;
  int every_ms = 20;
  std::string push;   // --push standing|walking|all: the largest impulse survived per direction instead
  std::string probe;  // --probe standing|walking,DEG,N_S: one push
  std::string trace;  // --trace FILE: the probe's walk status every 10 ms as CSV (tools: plot_walk_push.py)
  int trace_ms = 10;  // --trace-ms MS: ... every MS ms instead
  std::string stabilizer = "both";  // --stabilizer on|off|both (the push table and the arm swing)
  double resolution = 2.5;          // N s, of the push bisection
  double rtf = 0;     // --rtf S: S simulated seconds of walking per stabilizer setting, CPU per physics step
  bool arms = false;  // --arms 1: both arms swung together +-1 rad every 0.5 s, standing and walking
  unsigned seed = 1;
  int instants = 0;  // --instants K: the multi-instant push sweep (walking)
  std::vector<double> levels = {10, 15, 20, 25, 30, 40};  // --levels: its impulses, N s
  double cycle = 1.52;                                    // --cycle S: the span its instants cover
  bool nudge = false;  // --nudge 1: every push direction one ulp larger (how chaotic a figure is)
  double shift = 0;    // --shift S: every instant S s later (how steady a figure is)
  std::map<std::string, std::string> options = bench::DefaultWalkOptions();
};

Args Parse(int argc, char** argv) {
  Args a;
  bench::RequireFlagValuePairs(argc, argv);
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--transition") {
      a.transition = v;
    } else if (k == "--model") {
      a.model = v;
    } else if (k == "--from") {
      a.from = std::atof(v.c_str());
    } else if (k == "--span") {
      a.span = std::atof(v.c_str());
    } else if (k == "--every") {
      a.every_ms = std::atoi(v.c_str());
    } else if (k == "--push") {
      a.push = v;
    } else if (k == "--probe") {
      a.probe = v;
    } else if (k == "--trace") {
      a.trace = v;
    } else if (k == "--trace-ms") {
      a.trace_ms = std::atoi(v.c_str());
    } else if (k == "--stabilizer") {
      a.stabilizer = v;
    } else if (k == "--resolution") {
      a.resolution = std::atof(v.c_str());
    } else if (k == "--rtf") {
      a.rtf = std::atof(v.c_str());
    } else if (k == "--arms") {
      a.arms = v == "1";
    } else if (k == "--seed") {
      a.seed = static_cast<unsigned>(std::atoi(v.c_str()));
    } else if (k == "--instants") {
      a.instants = std::atoi(v.c_str());
    } else if (k == "--shift") {
      a.shift = std::atof(v.c_str());
    } else if (k == "--nudge") {
      a.nudge = v == "1";
    } else if (k == "--cycle") {
      a.cycle = std::atof(v.c_str());
    } else if (k == "--levels") {
      a.levels.clear();
      for (size_t at = 0; at < v.size();) {
        const size_t comma = std::min(v.find(',', at), v.size());
        a.levels.push_back(std::atof(v.substr(at, comma - at).c_str()));
        at = comma + 1;
      }
    } else if (k == "--after") {
      a.after = std::atof(v.c_str());
    } else if (k == "--option") {
      bench::SetDriverOption(a.options, v);
    } else {
      std::fprintf(stderr, "unknown argument %s\n", k.c_str());
      std::exit(2);
    }
  }
  if (a.every_ms <= 0 || a.trace_ms <= 0 || a.span < 0 || a.after <= 0 || !(a.resolution > 0)) {
    std::fprintf(stderr, "--every must be > 0 ms, --span >= 0, --after > 0, --resolution > 0\n");
    std::exit(2);
  }
  if (a.instants < 0 || a.instants > 50 || !(a.cycle > 0) || a.levels.empty() ||
      std::any_of(a.levels.begin(), a.levels.end(), [](double l) { return !(l > 0); })) {
    std::fprintf(stderr, "--instants in [0, 50], --cycle > 0, --levels N_S,... each > 0\n");
    std::exit(2);
  }
  if (a.stabilizer != "on" && a.stabilizer != "off" && a.stabilizer != "both") {
    std::fprintf(stderr, "--stabilizer on, off or both, not '%s'\n", a.stabilizer.c_str());
    std::exit(2);
  }
  return a;
}

struct Run {
  OdeDriver* ode;
  Driver* d;
  std::vector<Completion> done;
  CommandId id = 0;
  double max_tilt = 0;
  std::FILE* trace = nullptr;  // --trace: one CSV row per trace_ms
  int trace_ms = 10;
  void Exec(CommandType type, std::vector<double> values) {
    DriverCommand c;
    c.id = ++id;
    c.type = type;
    c.num_values = static_cast<int>(values.size());
    for (size_t i = 0; i < values.size(); ++i) c.values[i] = values[i];
    d->Execute(c, ode->sim_time(), done);
  }
  void Goto() { Exec(CommandType::kGoto, {1.0, 0, 0}); }
  void Speed(double v) { Exec(CommandType::kSetSpeed, {v, 0}); }
  void Joint(const char* name, double q) {
    DriverCommand c;
    c.id = ++id;
    c.type = CommandType::kJointSetPoint;
    c.target = ode->model().JointIndex(name);
    c.num_values = 1;
    c.values[0] = q;
    d->Execute(c, ode->sim_time(), done);
  }
  void Stop() { d->Stop(ode->sim_time(), done); }
  void Trace(const walking::WalkStatus& s) {
    std::fprintf(trace, "%.3f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,%d,%.4f",
                 ToSeconds(ode->sim_time().time_since_epoch()), s.com.x(), s.com.y(), s.com_plan.x(),
                 s.com_plan.y(), s.dcm.x(), s.dcm.y(), s.dcm_ref.x(), s.dcm_ref.y(), s.zmp.x(), s.zmp.y(),
                 s.zmp_ref.x(), s.zmp_ref.y(), s.zmp_command.x(), s.zmp_command.y(), s.saturated ? 1 : 0,
                 s.tilt);
    for (int i = 0; i < 2; ++i)
      std::fprintf(trace, ",%.5f,%.5f,%.5f,%.5f,%.2f", s.foot[i].x, s.foot[i].y, s.foot[i].theta,
                   s.foot_height[i], s.foot_force[i]);
    std::fprintf(trace, ",%.5f,%.5f", s.com_offset.x(), s.com_offset.y());
    // Appended (after the columns plot_walk_push.py reads): the measured
    // feet (x, y, yaw, sole tilt, contact points), steps started, recoveries.
    for (int i = 0; i < 2; ++i)
      std::fprintf(trace, ",%.5f,%.5f,%.5f,%.4f,%d", s.foot_measured[i].x, s.foot_measured[i].y,
                   s.foot_measured[i].theta, s.foot_tilt[i], s.foot_contacts[i]);
    std::fprintf(trace, ",%d,%d", s.steps_taken, s.recoveries);
    // Then the push stop's count, each sole's roll and ankle offsets (roll,
    // pitch), the force difference control's height (push_balance).
    std::fprintf(trace, ",%d", s.push_stops);
    for (int i = 0; i < 2; ++i)
      std::fprintf(trace, ",%.4f,%.4f,%.4f", s.foot_roll[i], s.ankle_offset[i].x(), s.ankle_offset[i].y());
    std::fprintf(trace, ",%.5f", s.force_difference);
    // Then each sole's lowest corner's height, largest one-contact force and pitch.
    for (int i = 0; i < 2; ++i)
      std::fprintf(trace, ",%.5f,%.1f,%.4f", s.foot_low[i], s.foot_peak_force[i], s.foot_pitch[i]);
    std::fprintf(trace, ",%d", s.push_timings);  // then push_step_timing's re-plans
    // Then whether a push's stop holds and the push detector's input (m/s).
    std::fprintf(trace, ",%d,%.4f,%.4f", s.push_holding ? 1 : 0, s.push_impulse.x(), s.push_impulse.y());
    std::fprintf(trace, ",%.3f\n", s.push_waited);  // then the event-driven stop's waits so far (s)
  }
  void Panic() {
    d->Halt(done);
    d->Resume();
  }
  // Steps to `t` s after t0; false once fallen.
  bool Until(TimePoint t0, double t) {
    while (ToSeconds(ode->sim_time() - t0) < t - 1e-9) {
      ode->Step(trace ? trace_ms : 10, done);
      const walking::WalkStatus s = *ode->walk_status();
      max_tilt = std::max(max_tilt, s.tilt);
      if (trace) Trace(s);
      if (s.fallen) return false;
    }
    return true;
  }
};

// --trace F: F.on.csv or F.off.csv for setting `s` with its header (Run::Trace's
// columns); nullptr without --trace; exits (status 1) when it cannot be written.
std::FILE* OpenTrace(const std::string& base, const std::map<std::string, std::string>& s) {
  if (base.empty()) return nullptr;
  const std::string name = base + (s.at("stabilizer") == "true" ? ".on.csv" : ".off.csv");
  std::FILE* trace = std::fopen(name.c_str(), "w");
  if (!trace) {
    std::fprintf(stderr, "cannot write %s\n", name.c_str());
    std::exit(1);
  }
  std::fprintf(trace,
               "t,com_x,com_y,com_plan_x,com_plan_y,dcm_x,dcm_y,dcm_ref_x,dcm_ref_y,cop_x,cop_y,zmp_ref_x,"
               "zmp_ref_y,zmp_cmd_x,zmp_cmd_y,saturated,tilt,lfoot_x,lfoot_y,lfoot_th,lfoot_h,lfoot_f,"
               "rfoot_x,rfoot_y,rfoot_th,rfoot_h,rfoot_f,offset_x,offset_y,lmeas_x,lmeas_y,lmeas_th,ltilt,"
               "lcontacts,"
               "rmeas_x,rmeas_y,rmeas_th,rtilt,rcontacts,steps,recoveries,push_stops,lroll,lankle_roll,"
               "lankle_pitch,rroll,rankle_roll,rankle_pitch,force_difference,llow,lpeak,lpitch,rlow,rpeak,"
               "rpitch,timings,holding,impulse_x,impulse_y,waited\n");
  return trace;
}

// SETSPEED's forward speed for "the gait's full speed": the driver clamps it.
constexpr double kFullSpeed = 1.0;

// A transition: the actions at their times (t = the swept instant).
struct Timed {
  double at;
  std::function<void(Run&)> act;
};
using Script = std::function<std::vector<Timed>(double t)>;

const std::map<std::string, Script>& Transitions() {
  static const std::map<std::string, Script> all = {
      {"stop_goto",
       [](double t) {
         return std::vector<Timed>{{0, [](Run& r) { r.Goto(); }},
                                   {t, [](Run& r) { r.Stop(); }},
                                   {t + 0.1, [](Run& r) { r.Goto(); }}};
       }},
      {"stop_wait_goto",
       [](double t) {
         return std::vector<Timed>{{0, [](Run& r) { r.Goto(); }},
                                   {t, [](Run& r) { r.Stop(); }},
                                   {t + 1.2, [](Run& r) { r.Goto(); }}};
       }},
      {"speed_zero_back",
       [](double t) {
         return std::vector<Timed>{{0, [](Run& r) { r.Speed(kFullSpeed); }},
                                   {t, [](Run& r) { r.Speed(0); }},
                                   {t + 1.0, [](Run& r) { r.Speed(kFullSpeed); }}};
       }},
      {"panic_reset_goto",
       [](double t) {
         return std::vector<Timed>{{0, [](Run& r) { r.Goto(); }},
                                   {t, [](Run& r) { r.Panic(); }},
                                   {t + 0.1, [](Run& r) { r.Goto(); }}};
       }},
      {"stop",
       [](double t) {
         return std::vector<Timed>{{0, [](Run& r) { r.Goto(); }}, {t, [](Run& r) { r.Stop(); }}};
       }},
  };
  return all;
}

// One run from a fresh driver; returns whether it fell, and the worst tilt.
std::unique_ptr<Driver> NewDriver(const Args& args);

bool FellOnce(const Args& args, const Script& script, double t, double* tilt) {
  std::unique_ptr<Driver> d = NewDriver(args);
  Run r{.ode = static_cast<OdeDriver*>(d.get()), .d = d.get()};
  r.ode->Step(1000, r.done);  // into the stance
  const TimePoint t0 = r.ode->sim_time();
  const std::vector<Timed> steps = script(t);
  bool ok = true;
  for (const Timed& a : steps) {
    ok = ok && r.Until(t0, a.at);
    if (ok) a.act(r);
  }
  ok = ok && r.Until(t0, steps.back().at + args.after);
  *tilt = r.max_tilt;
  return !ok;
}

std::unique_ptr<Driver> NewDriver(const Args& args) { return bench::NewOdeDriver(args.model, args.options); }

// Pushes the pelvis with `j` N s toward `angle` (rad from ahead) over 0.1 s from now.
void PushNow(Run& r, double angle, double j) {
  constexpr double kPushTime = 0.1;
  r.ode->PushForTesting(Eigen::Vector3d(std::cos(angle), std::sin(angle), 0) * (j / kPushTime),
                        FromSeconds(kPushTime));
}

// Survives an impulse of `j` N s toward `angle` (rad from ahead), pushed at `at` s?
bool SurvivesPush(const Args& args, bool walking, double angle, double j, double at,
                  std::FILE* trace = nullptr) {
  std::unique_ptr<Driver> d = NewDriver(args);
  Run r{.ode = static_cast<OdeDriver*>(d.get()), .d = d.get(), .trace = trace, .trace_ms = args.trace_ms};
  r.ode->Step(1000, r.done);
  const TimePoint t0 = r.ode->sim_time();
  if (walking) r.Speed(kFullSpeed);
  if (!r.Until(t0, at)) return false;
  PushNow(r, angle, j);
  return r.Until(t0, at + args.after);
}

// The stabilizer settings asked for (--stabilizer), as driver options.
std::vector<Args> Settings(const Args& args) {
  std::vector<Args> out;
  for (const char* on : {"off", "on"}) {
    if (args.stabilizer != "both" && args.stabilizer != on) continue;
    Args a = args;
    a.options["stabilizer"] = std::string(on) == "on" ? "true" : "false";
    out.push_back(a);
  }
  return out;
}

// The largest impulse survived to `resolution` in [0, kMaxPush] (a coarse bisection).
double Largest(const Args& args, bool walking, double angle, double at) {
  constexpr double kMaxPush = 80;
  if (SurvivesPush(args, walking, angle, kMaxPush, at)) return kMaxPush;
  double lo = 0, hi = kMaxPush;
  while (hi - lo > args.resolution) {
    const double mid = 0.5 * (lo + hi);
    (SurvivesPush(args, walking, angle, mid, at) ? lo : hi) = mid;
  }
  return lo;
}

int ArmSwing(const Args& args);

int Pushes(const Args& args) {
  if (args.push != "standing" && args.push != "walking" && args.push != "all") {
    std::fprintf(stderr, "--push standing, walking or all\n");
    return 2;
  }
  std::vector<std::pair<bool, const Args*>> columns;  // (walking, settings)
  const std::vector<Args> settings = Settings(args);
  std::printf("largest impulse survived (N s, 0.1 s push on the pelvis, bisection to %.2f N s)\n",
              args.resolution);
  std::printf("direction_deg");
  for (bool walking : {false, true}) {
    if (args.push != "all" && (args.push == "walking") != walking) continue;
    for (const Args& a : settings) {
      columns.emplace_back(walking, &a);
      std::printf("  %s_stab_%s", walking ? "walking" : "standing",
                  a.options.at("stabilizer") == "true" ? "on" : "off");
    }
  }
  std::printf("  push_at_s\n");
  std::mt19937 rng(args.seed);
  std::uniform_real_distribution<double> phase(0, 1.1);  // one gait period
  std::vector<double> worst(columns.size(), 1e9);
  for (int k = 0; k < 8; ++k) {
    const double angle = k * std::numbers::pi / 4;
    const double walk_at = 5.0 + phase(rng);
    std::printf("%13d", k * 45);
    for (size_t c = 0; c < columns.size(); ++c) {
      const double j = Largest(*columns[c].second, columns[c].first, angle, columns[c].first ? walk_at : 2.0);
      worst[c] = std::min(worst[c], j);
      std::printf("  %*.2f", 16, j);
      std::fflush(stdout);
    }
    std::printf("  %9.2f\n", walk_at);
  }
  std::printf("%13s", "min");
  for (double w : worst) std::printf("  %*.2f", 16, w);
  std::printf("\n\n");
  return ArmSwing(args);
}

// --push walking --instants K: per direction and impulse level, the fraction
// of K push instants survived (see the header). Each instant's walk is stepped
// to the push once; every (direction, level) is a forked child of it.
int MultiInstantPushes(const Args& args) {
  if (args.push != "walking") {
    std::fprintf(stderr, "--instants needs --push walking\n");
    return 2;
  }
  const int k_instants = args.instants, n_levels = static_cast<int>(args.levels.size());
  std::mt19937 rng(args.seed);
  std::uniform_real_distribution<double> jitter(0, 1);
  std::vector<double> at(k_instants);
  for (int i = 0; i < k_instants; ++i) at[i] = 5.0 + args.shift + args.cycle * (i + jitter(rng)) / k_instants;
  std::printf("push instants (s into the walk):");
  for (double t : at) std::printf(" %.6f", t);  // (--probe ...,AT with these lands on the same 10 ms step)
  std::printf("\n");
  const auto wall0 = std::chrono::steady_clock::now();
  const std::clock_t cpu0 = std::clock();
  int children = 0;
  for (const Args& s : Settings(args)) {
    // survived[direction][level][instant]
    std::vector<std::vector<std::vector<bool>>> survived(
        8, std::vector<std::vector<bool>>(n_levels, std::vector<bool>(k_instants, false)));
    for (int i = 0; i < k_instants; ++i) {
      std::unique_ptr<Driver> d = NewDriver(s);
      Run r{.ode = static_cast<OdeDriver*>(d.get()), .d = d.get()};
      r.ode->Step(1000, r.done);
      const TimePoint t0 = r.ode->sim_time();
      r.Speed(kFullSpeed);
      if (!r.Until(t0, at[i])) continue;  // fell unpushed: every cell of this instant counts as a fall
      for (int k = 0; k < 8; ++k) {
        double angle = k * 45.0 * std::numbers::pi / 180;  // as --probe computes it
        if (args.nudge) angle = std::nextafter(angle, 10.0);
        for (int l = 0; l < n_levels; ++l) {
          std::fflush(stdout);
          const pid_t pid = fork();
          if (pid < 0) {
            std::perror("fork");
            return 1;
          }
          if (pid == 0) {
            PushNow(r, angle, args.levels[l]);
            _exit(r.Until(t0, at[i] + args.after) ? 0 : 1);
          }
          int status = 0;
          if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) > 1) {
            std::fprintf(stderr, "push child %d failed (status %d)\n", static_cast<int>(pid), status);
            return 1;
          }
          survived[k][l][i] = WEXITSTATUS(status) == 0;
          ++children;
        }
      }
    }
    std::printf(
        "walking at full speed, stabilizer %s: instants survived of %d per impulse (N s), "
        "--after %.1f s\n",
        s.options.at("stabilizer") == "true" ? "on" : "off", k_instants, args.after);
    std::printf("direction_deg");
    for (double lv : args.levels) std::printf("  %5.0f", lv);
    std::printf("  median_largest  mean_largest\n");
    int total = 0;
    double sum_median = 0;
    for (int k = 0; k < 8; ++k) {
      std::printf("%13d", k * 45);
      for (int l = 0; l < n_levels; ++l) {
        const int n = static_cast<int>(std::count(survived[k][l].begin(), survived[k][l].end(), true));
        total += n;
        std::printf("  %2d/%-2d", n, k_instants);
      }
      // Per instant, the largest level survived below its first fall (0: the first fell).
      std::vector<double> largest(k_instants, 0);
      for (int i = 0; i < k_instants; ++i)
        for (int l = 0; l < n_levels && survived[k][l][i]; ++l) largest[i] = args.levels[l];
      std::vector<double> sorted = largest;
      std::sort(sorted.begin(), sorted.end());
      const double median = k_instants % 2 == 1 ? sorted[k_instants / 2]
                                                : 0.5 * (sorted[k_instants / 2 - 1] + sorted[k_instants / 2]);
      double mean = 0;
      for (double v : largest) mean += v / k_instants;
      sum_median += median;
      std::printf("  %14.1f  %12.1f\n", median, mean);
    }
    std::printf("survived %d of %d pushes; sum of the medians %.1f N s\n", total, 8 * n_levels * k_instants,
                sum_median);
    // Every push's outcome (S survived, F fell; the instants in order), for
    // comparing two settings push by push (the same instants, another binary).
    std::printf("cells (direction_deg N_s outcomes):\n");
    for (int k = 0; k < 8; ++k) {
      for (int l = 0; l < n_levels; ++l) {
        std::printf("cell %d %.0f ", k * 45, args.levels[l]);
        for (int i = 0; i < k_instants; ++i) std::printf("%c", survived[k][l][i] ? 'S' : 'F');
        std::printf("\n");
      }
    }
    std::printf("\n");
  }
  rusage ru{};
  getrusage(RUSAGE_CHILDREN, &ru);
  const double child_cpu =
      ru.ru_utime.tv_sec + ru.ru_stime.tv_sec + 1e-6 * (ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
  std::printf(
      "%d pushes (each <= %.1f s simulated after its walk's prefix): %.0f CPU s (walks %.0f, pushes %.0f), "
      "%.0f s wall\n",
      children, args.after, static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC + child_cpu,
      static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC, child_cpu,
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count());
  return 0;
}

// --push goto[,DEG,N_S]: the pushed GOTO at 21 instants (see the header).
int PushedGotos(const Args& args) {
  std::vector<std::pair<double, double>> pushes = {{90, 8}, {270, 8}};  // (deg, N s)
  int instants = 21;
  double first = 2.5;
  if (args.push != "goto") {
    std::vector<double> v;  // goto,DEG,N_S[,AT]
    for (size_t at = args.push.find(','); at != std::string::npos; at = args.push.find(',', at + 1))
      v.push_back(std::atof(args.push.c_str() + at + 1));
    if (args.push.substr(0, args.push.find(',')) != "goto" || v.size() < 2 || v.size() > 3) {
      std::fprintf(stderr, "--push goto, goto,DEG,N_S or goto,DEG,N_S,AT\n");
      return 2;
    }
    pushes = {{v[0], v[1]}};
    if (v.size() == 3) instants = 1, first = v[2];
  }
  if (!args.trace.empty() && instants != 1) {
    std::fprintf(stderr, "--trace with --push goto,DEG,N_S,AT (one instant)\n");
    return 2;
  }
  constexpr double kGoal = 1.5, kEvery = 0.05, kWait = 60, kArrived = 0.05;
  const int kInstants = instants;
  const double kFirst = first;
  std::printf(
      "pushed GOTO (%.1f m; a 0.1 s push on the pelvis %.2f-%.2f s after the command every %.0f ms; driver "
      "seed %s): F fell, . arrived (SUCCESS within %.0f cm), s no answer in %.0f s, x answered otherwise\n",
      kGoal, kFirst, kFirst + (kInstants - 1) * kEvery, kEvery * 1000,
      args.options.count("seed") ? args.options.at("seed").c_str() : "7", kArrived * 100, kWait);
  for (const auto& [deg, j] : pushes) {
    std::map<std::string, std::string> fell;  // per setting, the pattern's fell flags
    for (Args s : Settings(args)) {
      s.options.emplace("seed", "7");
      std::string pattern, when;
      for (int k = 0; k < kInstants; ++k) {
        std::unique_ptr<Driver> d = NewDriver(s);
        Run r{
            .ode = static_cast<OdeDriver*>(d.get()), .d = d.get(), .trace = OpenTrace(args.trace, s.options)};
        r.ode->Step(1, r.done);  // as the tests' Walker starts
        r.ode->Step(1000, r.done);
        const TimePoint t0 = r.ode->sim_time();
        r.Exec(CommandType::kGoto, {kGoal, 0, 0});
        bool ok = r.Until(t0, std::round((kFirst + k * kEvery) * 100) / 100);
        const TimePoint pushed = r.ode->sim_time();
        if (ok) PushNow(r, deg * std::numbers::pi / 180, j);
        while (ok && r.done.empty() && r.ode->sim_time() - pushed < FromSeconds(kWait))
          ok = r.Until(r.ode->sim_time(), 0.01);
        if (r.trace) std::fclose(r.trace);
        const walking::Pose2 p = r.ode->walk_status()->pelvis;
        char c = 'F';
        if (ok) {
          c = r.done.empty() ? 's' : 'x';
          if (r.done.size() == 1 && r.done[0].signal == Signal::kSuccess &&
              std::hypot(p.x - kGoal, p.y) < kArrived)
            c = '.';
        } else {
          char t[16];
          std::snprintf(t, sizeof t, " +%.2f", ToSeconds(r.ode->sim_time() - pushed));
          when += t;
        }
        pattern += c;
      }
      const auto n = [&](char c) { return std::count(pattern.begin(), pattern.end(), c); };
      std::printf(
          "%s  %.0f deg %.1f N s, stabilizer %s: %ld fell, %ld arrived, %ld no answer, %ld otherwise%s%s\n",
          pattern.c_str(), deg, j, s.options.at("stabilizer") == "true" ? "on" : "off", n('F'), n('.'),
          n('s'), n('x'), when.empty() ? "" : "; fell after the push at", when.c_str());
      std::fflush(stdout);
      fell[s.options.at("stabilizer")] = pattern;
    }
    if (fell.size() == 2) {  // McNemar on the falls, instant by instant
      int only_on = 0, only_off = 0;
      for (int k = 0; k < kInstants; ++k) {
        const bool on = fell["true"][k] == 'F', off = fell["false"][k] == 'F';
        only_on += on && !off;
        only_off += off && !on;
      }
      const double z = only_on + only_off > 0 ? (only_on - only_off) / std::sqrt(only_on + only_off) : 0.0;
      std::printf(
          "%*s  %.0f deg %.1f N s: fell only with the stabilizer %d, only without %d (McNemar z %.2f)\n",
          kInstants, "", deg, j, only_on, only_off, z);
    }
  }
  return 0;
}

// --probe standing|walking,DEG,N_S
int Probe(const Args& args) {
  const size_t a = args.probe.find(','), b = args.probe.rfind(',');
  if (a == std::string::npos || a == b) {
    std::fprintf(stderr, "--probe standing|walking,DEG,N_S\n");
    return 2;
  }
  const bool walking = args.probe.substr(0, a) == "walking";
  const double deg = std::atof(args.probe.substr(a + 1, args.probe.find(',', a + 1) - a - 1).c_str());
  const std::string rest = args.probe.substr(b + 1);
  // N_S or DEG,N_S,AT: then b pointed at AT's comma.
  double j = std::atof(rest.c_str()), at = walking ? 5.5 : 2.0;
  const size_t c = args.probe.find(',', a + 1);
  if (c != b) {
    j = std::atof(args.probe.substr(c + 1, b - c - 1).c_str());
    at = std::atof(rest.c_str());
  }
  for (const Args& s : Settings(args)) {
    std::FILE* trace = OpenTrace(args.trace, s.options);
    const bool ok = SurvivesPush(s, walking, deg * std::numbers::pi / 180, j, at, trace);
    if (trace) std::fclose(trace);
    std::printf("%s %.0f deg %.2f N s at %.2f s, stabilizer %s: %s\n", walking ? "walking" : "standing", deg,
                j, at, s.options.at("stabilizer").c_str(), ok ? "survived" : "FELL");
  }
  return 0;
}

// --rtf S: the cost of the walking controller: S s walking at full speed
// (after the 1 s stance), CPU time of this process per 1 ms physics step, with
// and without the stabilizer (the same physics and pattern).
int Rtf(const Args& args) {
  for (const Args& s : Settings(args)) {
    std::unique_ptr<Driver> d = NewDriver(s);
    Run r{.ode = static_cast<OdeDriver*>(d.get()), .d = d.get()};
    r.ode->Step(1000, r.done);
    r.Speed(kFullSpeed);
    const std::clock_t cpu0 = std::clock();
    const int steps = static_cast<int>(args.rtf * 1000);
    r.ode->Step(steps, r.done);
    const double cpu = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    std::printf(
        "walking %.0f s, stabilizer %s: %.1f us CPU per 1 ms step, real-time factor %.2f per CPU second%s\n",
        args.rtf, s.options.at("stabilizer") == "true" ? "on" : "off", cpu / steps * 1e6, args.rtf / cpu,
        r.ode->walk_status()->fallen ? " (FELL)" : "");
  }
  return 0;
}

int ArmSwing(const Args& args) {
  for (const Args& s : Settings(args)) {
    for (bool walking : {false, true}) {
      std::unique_ptr<Driver> d = NewDriver(s);
      Run r{.ode = static_cast<OdeDriver*>(d.get()), .d = d.get()};
      r.ode->Step(1000, r.done);
      const TimePoint t0 = r.ode->sim_time();
      if (walking) r.Speed(kFullSpeed);
      bool ok = r.Until(t0, 2.0);
      for (int i = 0; ok && i < 12; ++i) {
        const double q = i % 2 == 0 ? 1.0 : -1.0;
        r.Joint("left_shoulder_pitch", q);
        r.Joint("right_shoulder_pitch", q);
        ok = r.Until(t0, 2.5 + 0.5 * i);
      }
      ok = ok && r.Until(t0, 9.0);
      std::printf("arms swung +-1 rad every 0.5 s, %s, stabilizer %s: %s (worst tilt %.3f rad)\n",
                  walking ? "walking" : "standing", s.options.at("stabilizer") == "true" ? "on" : "off",
                  ok ? "stood" : "FELL", r.max_tilt);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = Parse(argc, argv);
  if (!args.probe.empty()) return Probe(args);
  if (args.rtf > 0) return Rtf(args);
  if (args.push.rfind("goto", 0) == 0) return PushedGotos(args);
  if (!args.push.empty()) return args.instants > 0 ? MultiInstantPushes(args) : Pushes(args);
  if (args.arms) return ArmSwing(args);
  if (args.transition != "all" && !Transitions().count(args.transition)) {
    std::fprintf(stderr, "unknown transition %s\n", args.transition.c_str());
    return 2;
  }
  const int n = static_cast<int>(std::floor(args.span * 1000 / args.every_ms + 1e-9)) + 1;
  std::printf("transition        runs  falls  worst_tilt_rad  fell_at_s\n");
  int total_falls = 0;
  const std::clock_t cpu0 = std::clock();
  double simulated = 0;
  for (const auto& [name, script] : Transitions()) {
    if (args.transition != "all" && args.transition != name) continue;
    int falls = 0;
    double worst = 0;
    std::string fell_at;
    for (int i = 0; i < n; ++i) {
      const double t = args.from + i * args.every_ms * 1e-3;
      double tilt = 0;
      if (FellOnce(args, script, t, &tilt)) {
        ++falls;
        char at[16];
        std::snprintf(at, sizeof at, " %.2f", t);
        fell_at += at;
      }
      worst = std::max(worst, tilt);
      simulated += 1.0 + script(t).back().at + args.after;
    }
    total_falls += falls;
    std::printf("%-16s  %4d  %5d  %14.3f %s\n", name.c_str(), n, falls, worst, fell_at.c_str());
    std::fflush(stdout);
  }
  const double cpu = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
  std::printf("\nfalls %d; %.0f simulated s in %.0f CPU s (%.1f per CPU second)\n", total_falls, simulated,
              cpu, simulated / cpu);
  return total_falls == 0 ? 0 : 1;
}

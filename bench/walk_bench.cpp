// Benchmark of the walking humanoid on ODE (not a test): N seeded GOTO goals
// (up to 2 m away, any heading) walked one after another by
// models/simple_humanoid.urdf on the ode driver at 1 kHz; prints per goal the
// answer, end error, walking time and speed, falls, and the real-time factor;
// optionally writes a trace of one walk (footsteps, ZMP, CoM) for plotting.
// Figures go to docs/ode_sim.md ("Walking"). Another humanoid: --model URDF
// and its driver options, e.g. --model ../shared/robots/atlas.urdf --option
// base=floating ("Published humanoids").
//   robotalk-walk-bench [--model URDF] [--goals N] [--seed S] [--trace CSV] [--trace-goal K]
//                       [--option key=value]... [--goal x,y,theta] [--stop S] [--verbose N] [--stand S]
//                       [--timeout S] [--speeds N]
// Diagnostics: --goal walks to one goal relative to the start instead;
// --stop sends STOP S seconds into each walk; --verbose prints the measured
// and planned state every N x 10 ms (pelvis, tilt, CoM error, feet, sole
// tilts, centre of pressure, contact forces and counts, tracking error);
// --timeout S (default 120): a GOTO still running after S simulated seconds
// is stopped and counts as TIMEOUT, a failure;
// --stand prints S seconds of the start-up stance first.
// --speeds N: instead of goals, the steady SETSPEED speeds: per direction
// (forward, back, left, right, turn left, turn right; each asked far above
// the gait's limit, so clamped to it) from a fresh driver, the pelvis'
// displacement (in the start's frame) and turn over N pairs of steps (from
// the lift-off of the 4th step to that of the (4 + 2N)th: the sway at the
// same phase at both ends), then STOP; falls, worst tilt and the centre of pressure from the
// plan's ZMP while stepping.
#include "ode_driver.h"
#include "walk_bench_util.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <vector>

using namespace robotalk;
using WallClock = std::chrono::steady_clock;

namespace {

struct Args {
  std::string model = bench::DefaultWalkModel();
  int goals = 20;
  unsigned seed = 1;
  std::string trace;
  int trace_goal = 0;
  int stand = 0;  // --stand S: seconds to stand and print before the goals
  bool fixed_goal = false;
  double goal[3] = {0, 0, 0};  // --goal x,y,theta: one goal instead of random ones
  double timeout = 120;        // --timeout S: simulated seconds a GOTO may run before it counts as TIMEOUT
  int verbose = 0;             // --verbose N: print the walk every N x 10 ms
  double stop_after = -1;      // --stop S: STOP each walk S s after its GOTO (then wait for standing)
  int speeds = 0;              // --speeds N: the steady SETSPEED table over N pairs of steps per direction
  std::map<std::string, std::string> options = bench::DefaultWalkOptions();
};

Args Parse(int argc, char** argv) {
  Args a;
  bench::RequireFlagValuePairs(argc, argv);
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--model") {
      a.model = v;
    } else if (k == "--goals") {
      a.goals = std::atoi(v.c_str());
    } else if (k == "--seed") {
      a.seed = static_cast<unsigned>(std::atoi(v.c_str()));
    } else if (k == "--trace") {
      a.trace = v;
    } else if (k == "--stand") {
      a.stand = std::atoi(v.c_str());
    } else if (k == "--goal") {
      a.fixed_goal = std::sscanf(v.c_str(), "%lf,%lf,%lf", &a.goal[0], &a.goal[1], &a.goal[2]) == 3;
    } else if (k == "--stop") {
      a.stop_after = std::atof(v.c_str());
    } else if (k == "--verbose") {
      a.verbose = std::atoi(v.c_str());
    } else if (k == "--timeout") {
      a.timeout = std::atof(v.c_str());
    } else if (k == "--speeds") {
      a.speeds = std::atoi(v.c_str());
    } else if (k == "--trace-goal") {
      a.trace_goal = std::atoi(v.c_str());
    } else if (k == "--option") {
      bench::SetDriverOption(a.options, v);
    } else {
      std::fprintf(stderr, "unknown argument %s\n", k.c_str());
      std::exit(2);
    }
  }
  return a;
}

void PrintStand(OdeDriver* ode) {
  const walking::WalkStatus s = *ode->walk_status();
  RobotState st;
  ode->ReadState(st);
  const RobotModel& m = ode->model();
  const auto q = [&](const char* joint) { return st.position[m.dof_offset(m.JointIndex(joint))]; };
  std::printf(
      "stand t=%.2f tilt %.4f com %.4f %.4f %.4f pelvis %.4f %.4f %.4f  hip %.3f knee %.3f ankle %.3f "
      "foot %.4f zmp %.4f plan %.4f F %.0f/%d\n",
      ToSeconds(ode->sim_time().time_since_epoch()), s.tilt, s.com.x(), s.com.y(), s.com.z(), s.pelvis.x,
      s.pelvis.y, s.pelvis.theta, q("left_hip_pitch"), q("left_knee"), q("left_ankle_pitch"),
      s.foot_measured[0].x, s.zmp.x(), s.zmp_ref.x(), s.foot_force[0], s.foot_contacts[0]);
}

void PrintWalk(const walking::WalkStatus& s, double t) {
  std::printf(
      "  t=%.2f pelvis %.3f %.3f %.3f tilt %.3f com-plan %.3f %.3f steps %d"
      " L %.3f %.3f %.3f/%.3f h%.3f  R %.3f %.3f %.3f/%.3f h%.3f tilts %.3f %.3f"
      " zmp %.3f %.3f plan %.3f %.3f F %.0f/%d %.0f/%d trk %.3f%s\n",
      t, s.pelvis.x, s.pelvis.y, s.pelvis.theta, s.tilt, s.com.x() - s.com_plan.x(),
      s.com.y() - s.com_plan.y(), s.steps_taken, s.foot_measured[0].x, s.foot_measured[0].y,
      s.foot_measured[0].theta, s.foot[0].theta, s.foot_height[0], s.foot_measured[1].x, s.foot_measured[1].y,
      s.foot_measured[1].theta, s.foot[1].theta, s.foot_height[1], s.foot_tilt[0], s.foot_tilt[1], s.zmp.x(),
      s.zmp.y(), s.zmp_ref.x(), s.zmp_ref.y(), s.foot_force[0], s.foot_contacts[0], s.foot_force[1],
      s.foot_contacts[1], s.tracking_error, s.fallen ? " FALLEN" : "");
}

void WriteTrace(std::ofstream& trace, const walking::WalkStatus& s, double t) {
  trace << t << ',' << s.foot[0].x << ',' << s.foot[0].y << ',' << s.foot[0].theta << ',' << s.foot_height[0]
        << ',' << s.foot[1].x << ',' << s.foot[1].y << ',' << s.foot[1].theta << ',' << s.foot_height[1]
        << ',' << s.zmp_ref.x() << ',' << s.zmp_ref.y() << ',' << s.com_plan.x() << ',' << s.com_plan.y()
        << ',' << s.com.x() << ',' << s.com.y() << ',' << s.pelvis.x << ',' << s.pelvis.y << ',' << s.zmp.x()
        << ',' << s.zmp.y() << '\n';
}

struct Outcome {
  Signal signal = Signal::kError;
  std::string message;
  bool timed_out = false;    // still running after --timeout: neither a success nor an answer
  double sim = 0, wall = 0;  // s
};

// One GOTO to c (values x y theta): steps until it completes, a fall, or
// (--stop) the end of the stepping after a STOP. A GOTO still running after
// --timeout is stopped and reported TIMEOUT (a failure), whatever it answers then.
// The measured centre of pressure against the plan's ZMP and the
// stabilizer's ZMP command, every 10 ms while stepping (m).
// Per foot carrying more than kLoaded N: its CoP from where it should press
// (walking/foot_damping.h's split of the ZMP) and its roll and pitch.
struct CopErrors {
  static constexpr double kLoaded = 50;  // N
  std::vector<double> to_plan, to_command, foot_cop, foot_roll, foot_pitch;
  void Add(const walking::WalkStatus& s) {
    if (!s.stepping) return;
    to_plan.push_back((s.zmp - s.zmp_ref).norm());
    if (s.zmp_command.norm() > 0) to_command.push_back((s.zmp - s.zmp_command).norm());
    for (int i = 0; i < 2; ++i) {
      if (s.foot_force[i] < kLoaded) continue;
      foot_cop.push_back((s.foot_cop[i] - s.foot_cop_ref[i]).norm());
      foot_roll.push_back(std::abs(s.foot_roll[i]));
      foot_pitch.push_back(std::abs(s.foot_pitch[i]));
    }
  }
};
CopErrors cop_errors;

// "median a / 95th b / max c cm" of v.
// (scale, unit: "cm" of metres by default; 1 and "rad" for angles.)
std::string Percentiles(std::vector<double> v, double scale = 100, const char* unit = "cm") {
  if (v.empty()) return "none";
  std::sort(v.begin(), v.end());
  const auto at = [&](double p) {
    return scale * v[static_cast<size_t>(p * static_cast<double>(v.size() - 1))];
  };
  char out[112];
  const int digits = scale >= 100 ? 2 : 3;
  std::snprintf(out, sizeof out, "median %.*f / 95th %.*f / max %.*f %s (%zu samples)", digits, at(0.5),
                digits, at(0.95), digits, at(1.0), unit, v.size());
  return out;
}

Outcome WalkTo(Driver* d, OdeDriver* ode, const DriverCommand& c, const Args& args, std::ofstream* trace) {
  std::vector<Completion> done;
  const TimePoint t0 = ode->sim_time();
  const auto w0 = WallClock::now();
  const DriverResult res = d->Execute(c, t0, done);
  Outcome out{.signal = res.signal, .message = res.message};
  bool stopped = false;
  const int max_iterations = static_cast<int>(args.timeout * 100);
  int i = 0;
  for (; res.in_progress && (done.empty() || stopped) && i < max_iterations; ++i) {
    const double t = ToSeconds(ode->sim_time() - t0);
    if (!stopped && args.stop_after >= 0 && t >= args.stop_after) {
      d->Stop(ode->sim_time(), done);
      stopped = true;
    }
    if (ode->walk_status()->fallen) break;
    if (stopped && !ode->walk_status()->stepping && t > args.stop_after + 3) break;
    ode->Step(10, done);
    cop_errors.Add(*ode->walk_status());
    if (args.verbose > 0 && i % args.verbose == 0) PrintWalk(*ode->walk_status(), t + 0.01);
    if (trace && i % 2 == 0) WriteTrace(*trace, *ode->walk_status(), t + 0.01);
  }
  out.wall = std::chrono::duration<double>(WallClock::now() - w0).count();
  out.sim = ToSeconds(ode->sim_time() - t0);
  if (res.in_progress && done.empty() && !stopped && i >= max_iterations) {
    out.timed_out = true;
    d->Stop(ode->sim_time(), done);  // the walk must not go on into the next goal
    ode->Step(5000, done);
  }
  if (!done.empty()) {
    out.signal = done[0].signal;
    out.message = done[0].message;
  }
  if (out.timed_out) out.message = "still running after " + std::to_string(args.timeout) + " s";
  return out;
}

// --speeds: the steady SETSPEED table; returns the falls.
int SpeedTable(const Args& args) {
  struct Direction {
    const char* name;
    double v, vy, omega;
  };
  const Direction dirs[] = {{"forward", 9, 0, 0}, {"back", -9, 0, 0},     {"left", 0, 9, 0},
                            {"right", 0, -9, 0},  {"turn left", 0, 0, 9}, {"turn right", 0, 0, -9}};
  std::printf(
      "direction    along_m/s  side_m/s  turn_rad/s  max_tilt  fell  CoP-to-plan  (SETSPEED answer)\n");
  int falls = 0;
  for (const Direction& dir : dirs) {
    std::unique_ptr<Driver> d = bench::NewOdeDriver(args.model, args.options);
    auto* ode = static_cast<OdeDriver*>(d.get());
    std::vector<Completion> done;
    ode->Step(1500, done);
    DriverCommand c;
    c.id = 1;
    c.type = CommandType::kSetSpeed;
    c.num_values = 3;
    c.values[0] = dir.v;
    c.values[1] = dir.vy;
    c.values[2] = dir.omega;
    const DriverResult r = d->Execute(c, ode->sim_time(), done);
    CopErrors cop;
    double tilt = 0, yaw = 0, last = ode->walk_status()->pelvis.theta;  // yaw: unwrapped
    const auto run = [&](double seconds, auto until) {
      for (int i = 0; i < static_cast<int>(seconds * 100) && !until(); ++i) {
        ode->Step(10, done);
        const walking::WalkStatus s = *ode->walk_status();
        tilt = std::max(tilt, s.tilt);
        yaw += walking::Wrap(s.pelvis.theta - last);
        last = s.pelvis.theta;
        if (s.fallen) return;
        cop.Add(s);
      }
    };
    run(20, [&] { return ode->walk_status()->steps_taken >= 3 || ode->walk_status()->fallen; });
    const walking::Pose2 p0 = ode->walk_status()->pelvis;
    const TimePoint t0 = ode->sim_time();
    const double yaw0 = yaw;
    // Whole pairs of steps, lift-off to lift-off: the sway is at the same phase at both ends.
    const int until_steps = ode->walk_status()->steps_taken + 2 * args.speeds;
    run(60, [&] { return ode->walk_status()->fallen || ode->walk_status()->steps_taken >= until_steps; });
    const walking::Pose2 p1 = ode->walk_status()->pelvis;
    const double yaw1 = yaw;
    const double dt = ToSeconds(ode->sim_time() - t0);
    const double c0 = std::cos(p0.theta), s0 = std::sin(p0.theta);
    const double along = (c0 * (p1.x - p0.x) + s0 * (p1.y - p0.y)) / dt;
    const double side = (-s0 * (p1.x - p0.x) + c0 * (p1.y - p0.y)) / dt;
    const double turn = (yaw1 - yaw0) / dt;
    d->Stop(ode->sim_time(), done);
    run(10, [&] { return !ode->walk_status()->stepping || ode->walk_status()->fallen; });
    run(1, [] { return false; });
    const bool fell = ode->walk_status()->fallen;
    falls += fell ? 1 : 0;
    std::printf("%-11s  %9.3f  %8.3f  %10.3f  %8.3f  %-4s  %s  (%s %s)\n", dir.name, along, side, turn, tilt,
                fell ? "yes" : "no", Percentiles(cop.to_plan).c_str(),
                std::string(ToString(r.signal)).c_str(), r.message.c_str());
    std::fflush(stdout);
  }
  return falls;
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = Parse(argc, argv);
  if (args.speeds > 0) return SpeedTable(args) == 0 ? 0 : 1;
  std::unique_ptr<Driver> d = bench::NewOdeDriver(args.model, args.options);
  auto* ode = static_cast<OdeDriver*>(d.get());
  if (!ode->walk_status()) {
    std::fprintf(stderr, "%s does not walk on the ode driver\n", args.model.c_str());
    return 1;
  }
  std::vector<Completion> none;
  for (int i = 0; i < 15 + args.stand * 10; ++i) {  // settle into the stance (--stand: and print it)
    ode->Step(args.stand > 0 ? 20 : 100, none);
    if (args.stand > 0) PrintStand(ode);
  }
  std::mt19937 rng(args.seed);
  std::uniform_real_distribution<double> dist(0.2, 2.0), angle(-std::numbers::pi, std::numbers::pi);
  std::ofstream trace;
  if (!args.trace.empty()) {
    trace.open(args.trace);
    trace << "t,lx,ly,lth,lh,rx,ry,rth,rh,zmp_x,zmp_y,com_plan_x,com_plan_y,com_x,com_y,pelvis_x,pelvis_y,"
             "zmp_meas_x,zmp_meas_y\n";
  }
  const std::clock_t cpu0 = std::clock();  // this process's CPU time: the RTF without the machine's load
  int successes = 0, falls = 0;
  double worst_d = 0, worst_th = 0, sum_d = 0, walked = 0, walk_time = 0, wall_total = 0;
  std::printf(
      "goal  x        y        theta    answer       time_s  dist_m  speed_m/s  end_err_m  end_err_rad  "
      "rtf\n");
  for (int g = 0; g < args.goals; ++g) {
    const walking::Pose2 start = ode->walk_status()->pelvis;
    double r = dist(rng);
    const double bearing = angle(rng), heading = angle(rng);
    DriverCommand c;
    c.id = g + 1;
    c.type = CommandType::kGoto;
    c.num_values = 3;
    c.values[0] = start.x + (args.fixed_goal ? args.goal[0] : r * std::cos(bearing));
    c.values[1] = start.y + (args.fixed_goal ? args.goal[1] : r * std::sin(bearing));
    c.values[2] = args.fixed_goal ? args.goal[2] : heading;
    if (args.fixed_goal) r = std::hypot(args.goal[0], args.goal[1]);
    const Outcome o =
        WalkTo(d.get(), ode, c, args, trace.is_open() && g == args.trace_goal ? &trace : nullptr);
    const walking::WalkStatus s = *ode->walk_status();
    const double ed = std::hypot(s.pelvis.x - c.values[0], s.pelvis.y - c.values[1]);
    const double eth = std::abs(walking::Wrap(s.pelvis.theta - c.values[2]));
    if (s.fallen) ++falls;
    if (o.signal == Signal::kSuccess && !o.timed_out) ++successes;
    worst_d = std::max(worst_d, ed);
    worst_th = std::max(worst_th, eth);
    sum_d += ed;
    walked += r;
    walk_time += o.sim;
    wall_total += o.wall;
    std::printf("%-4d  %7.3f  %7.3f  %7.3f  %-11s  %6.1f  %6.3f  %9.3f  %9.4f  %11.5f  %4.1f %s\n", g,
                c.values[0], c.values[1], c.values[2],
                o.timed_out ? "TIMEOUT" : std::string(ToString(o.signal)).c_str(), o.sim, r, r / o.sim, ed,
                eth, o.sim / o.wall, o.message.c_str());
    std::fflush(stdout);
    if (s.fallen) break;
  }
  std::printf(
      "\nsuccess %d/%d, falls %d, end error mean %.4f m, worst %.4f m and %.5f rad, "
      "mean speed %.3f m/s (straight-line distance / walking time), real-time factor %.1f at 1 kHz "
      "(%.1f per CPU second of this process)\n",
      successes, args.goals, falls, sum_d / args.goals, worst_d, worst_th, walked / walk_time,
      walk_time / wall_total, walk_time / (static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC));
  std::printf("centre of pressure from the plan's ZMP while stepping: %s\n",
              Percentiles(cop_errors.to_plan).c_str());
  std::printf("centre of pressure from the stabilizer's ZMP command while stepping: %s\n",
              Percentiles(cop_errors.to_command).c_str());
  std::printf("each loaded sole's centre of pressure from its share of the ZMP while stepping: %s\n",
              Percentiles(cop_errors.foot_cop).c_str());
  std::printf("each loaded sole's |roll|: %s\n", Percentiles(cop_errors.foot_roll, 1, "rad").c_str());
  std::printf("each loaded sole's |pitch|: %s\n", Percentiles(cop_errors.foot_pitch, 1, "rad").c_str());
  return successes == args.goals && falls == 0 ? 0 : 1;
}

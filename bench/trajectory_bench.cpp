// Issue 22's figures (not a test; scripts/bench.sh runs it, docs/performance.md
// "Trajectories (issue 22)"). Everything runs in-process: a RobotDaemon on a
// ManualClock (tests/support/sine_stream.h), no network.
//   robotalk-trajectory-bench SHARED_ROBOTS_DIR [--csv FILE] [--quick] [--cost-only]
// (a) the iiwa14 sine (0.5 Hz, 0.5 rad, on iiwa_joint_6) streamed by a
//     delay-mode client (300 ms ahead) at 10 Hz and 100 Hz frames, on the
//     kinematic and ODE drivers, step / linear / cubic / quintic: max and RMS
//     error of the measured joint against the continuous sine, every control
//     period after a settling second. --csv writes the ODE 10 Hz step and
//     quintic runs (for docs/figures/trajectory_ode_10hz.png).
// (b) the receding-horizon client: every 10 ms a 200 ms quintic trajectory
//     starting 20 ms ahead, each batch arriving 5 ms ± 3 ms late (seeded,
//     uniform), 10,000 splices: the largest velocity step of the reference
//     between consecutive periods against one period's worth of the
//     acceleration limit, and freezes.
// (c) the RobotDaemon's cost per 1 ms period with 31 dofs interpolating beside
//     the same daemon idle and a bare driver loop, and the allocations per period.
#include "kinematic_driver.h"
#include "ode_driver.h"
#include "robotalk/urdf_import.h"
#include "support/sine_stream.h"
#include "trajectory_tracker.h"

#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <string>

// Every heap allocation, not only operator new's: Eigen's matrices allocate
// with malloc (tests/support/allocation_counter counts both).
#include "support/allocation_counter.h"  // g_mallocs

using namespace robotalk;
using robotalk::testing::ManualDaemon;
using robotalk::testing::RunSineStream;
using robotalk::testing::SineResult;
using robotalk::testing::SineStream;
using WallClock = std::chrono::steady_clock;

namespace {

constexpr char kJoint[] = "iiwa_joint_6";
constexpr Interpolation kAll[] = {Interpolation::kStep, Interpolation::kLinear, Interpolation::kCubic,
                                  Interpolation::kQuintic};

std::unique_ptr<Driver> MakeDriver(const std::string& name, const std::string& urdf,
                                   std::map<std::string, std::string> options = {}) {
  DriverRegistry registry;
  RegisterKinematicDriver(registry);
  RegisterOdeDriver(registry);
  return registry.Create(name,
                         DriverConfig{.robot_name = "", .urdf_path = urdf, .options = std::move(options)});
}

void SineTable(const std::string& urdf, const std::string& csv) {
  std::printf(
      "| driver | frames | interpolation | max error (rad) | RMS error (rad) | answers S/M/other |\n");
  std::printf("|---|---|---|---|---|---|\n");
  SineResult ode10_step, ode10_quintic;
  for (const char* driver : {"kinematic", "ode"}) {
    for (double hz : {10.0, 100.0}) {
      for (Interpolation in : kAll) {
        // The kinematic driver at a 1 ms period, so the reference is seen between the waypoints too (at
        // 10 ms it would be seen at 100 Hz waypoints only); the ODE driver at its default 10 ms.
        auto d = std::strcmp(driver, "kinematic") == 0 ? MakeDriver(driver, urdf, {{"period_ms", "1"}})
                                                       : MakeDriver(driver, urdf);
        SineStream s;
        s.joint = d->model().JointIndex(kJoint);
        s.interpolation = in;
        s.frame_hz = hz;
        s.seconds = 6;
        const SineResult r = RunSineStream(std::move(d), s);
        std::printf("| %s | %.0f Hz | %s | %.5f | %.5f | %d/%d/%d |\n", driver, hz,
                    std::string(InterpolationName(in)).c_str(), r.max_error, r.rms_error, r.succeeded,
                    r.modified, r.other);
        if (std::strcmp(driver, "ode") == 0 && hz == 10.0 && in == Interpolation::kStep) ode10_step = r;
        if (std::strcmp(driver, "ode") == 0 && hz == 10.0 && in == Interpolation::kQuintic) ode10_quintic = r;
      }
    }
  }
  if (!csv.empty()) {
    std::ofstream f(csv);
    f << "time_s,sine,step,quintic\n";
    for (std::size_t i = 0; i < ode10_step.time.size() && i < ode10_quintic.time.size(); ++i) {
      f << ode10_step.time[i] << ',' << ode10_step.sine[i] << ',' << ode10_step.measured[i] << ','
        << ode10_quintic.measured[i] << '\n';
    }
  }
}

// (b): kinematic iiwa14 (it follows the reference exactly; the figure is the
// reference's, which the server computes the same for any driver). The
// client's ticks are 3.7 ms off the control periods, as a real client's are.
void RecedingHorizon(const std::string& urdf, int splices) {
  ManualDaemon d(MakeDriver("kinematic", urdf));
  const int joint = d.model().JointIndex(kJoint);
  const int dof = d.model().dof_offset(joint);
  const TimePoint t0 = ManualDaemon::Origin();
  const auto target = [&](TimePoint t) { return 0.5 * std::sin(std::numbers::pi * ToSeconds(t - t0)); };
  std::mt19937_64 rng(22);
  std::uniform_int_distribution<int> jitter_us(2000, 8000);  // 5 ms ± 3 ms
  const Duration tick = std::chrono::milliseconds(10);
  const double amax = RobotDaemonOptions{}.max_acceleration;
  double max_dv = 0, last_v = NAN, last_p = NAN, max_jitter = 0;
  int frozen = 0, missing = 0, modified_before = -1;
  CommandId id = 0;
  TimePoint control = t0;  // the next control period
  for (int i = 0; i < splices; ++i) {
    const TimePoint sent = t0 + std::chrono::microseconds(3700) + i * tick;  // not on the control periods
    const TimePoint arrives = sent + std::chrono::microseconds(jitter_us(rng));
    max_jitter = std::max(max_jitter, ToSeconds(arrives - sent));
    // The control periods before the batch arrives, then the arrival.
    for (; control < arrives; control += d.period()) {
      d.RunTo(control);
      if (control < t0 + std::chrono::seconds(1)) continue;  // from rest onto the sine: limited at first
      if (modified_before < 0) modified_before = d.modified;
      if (d.driver().ref_time(dof) != control) {
        ++missing;
        continue;
      }
      const double p = d.driver().ref_position(dof), v = d.driver().ref_velocity(dof);
      if (!std::isnan(last_v)) max_dv = std::max(max_dv, std::abs(v - last_v));
      if (p == last_p) ++frozen;
      last_v = v;
      last_p = p;
    }
    d.clock().Set(arrives);
    for (int k = 0; k < 20; ++k) {  // 200 ms: 20 waypoints from 20 ms ahead
      const TimePoint at = sent + std::chrono::milliseconds(20 + 10 * k);
      d.daemon().Submit(ManualDaemon::Waypoint(++id, joint, at, target(at), Interpolation::kQuintic));
    }
    d.RunTo(arrives);
  }
  std::printf(
      "receding horizon, kinematic iiwa14 '%s': %d splices (every 10 ms a 200 ms quintic trajectory from 20 "
      "ms "
      "ahead; arrival 5 ms ± 3 ms late, uniform, seeded, max %.1f ms): largest velocity step between periods "
      "%.4f rad/s against one period's worth of the acceleration limit %.4f rad/s (%.0f rad/s² × %.0f ms); "
      "freezes %d; periods without a reference %d (both from the first second on); answers "
      "SUCCESS/MODIFIED/other %d/%d/%d (MODIFIED from the first second on: %d; other: the replaced "
      "waypoints, "
      "INTERRUPTED)\n",
      kJoint, splices, 1e3 * max_jitter, max_dv, amax * ToSeconds(d.period()), amax,
      1e3 * ToSeconds(d.period()), frozen, missing, d.succeeded, d.modified, d.other,
      d.modified - modified_before);
}

// (c): a 31-joint chain (revolute, ±3 rad, 4 rad/s) on the kinematic driver at 1 ms.
RobotModel Chain(int joints) {
  RobotModelBuilder b("chain");
  b.AddLink(Link{.name = "l0"});
  for (int j = 0; j < joints; ++j) {
    const std::string parent = "l" + std::to_string(j), child = "l" + std::to_string(j + 1);
    b.AddLink(Link{.name = child});
    Joint joint{.name = "j" + std::to_string(j), .servo_types = ServoType::kSetPoint};
    joint.dofs = {Dof{.axis = j % 2 ? Eigen::Vector3d::UnitY() : Eigen::Vector3d::UnitZ(),
                      .limits = {.lower = -3, .upper = 3, .velocity = 4}}};
    b.AddJoint(joint, parent, child);
  }
  b.SetRoot("l0", Pose{}, BaseType::kFixed);
  return b.Build();
}

// Per-period wall times and allocations, apart for the periods in which
// waypoints arrived (the RobotDaemon takes them into the trajectories then).
struct Cost {
  std::vector<double> plain_us, arrival_us;
  long plain_allocations = 0, arrival_allocations = 0;
  double sum_us = 0;
  long periods = 0;
};

double Percentile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[static_cast<std::size_t>(k)];
}

void DaemonCost(int rounds) {
  constexpr int kJoints = 31, kPeriods = 1000;
  const KinematicDriverOptions options{.period = std::chrono::milliseconds(1)};
  ManualDaemon busy(std::make_unique<KinematicDriver>(Chain(kJoints), options));
  ManualDaemon idle(std::make_unique<KinematicDriver>(Chain(kJoints), options));
  KinematicDriver bare(Chain(kJoints), options);
  RobotState bare_state;
  std::vector<Completion> done;
  const TimePoint t0 = ManualDaemon::Origin();
  const auto wave = [&](int j, TimePoint t) {
    return 0.5 * std::sin(std::numbers::pi * ToSeconds(t - t0) + j);
  };
  CommandId id = 0;
  Cost c_busy, c_idle, c_bare;
  for (Cost* c : {&c_busy, &c_idle, &c_bare})
    c->plain_us.reserve(static_cast<std::size_t>(rounds * kPeriods));
  c_busy.arrival_us.reserve(static_cast<std::size_t>(rounds * kPeriods));
  TimePoint t = t0;
  const auto stream = [&](TimePoint now) {  // a delay-mode client at 100 Hz, 100 ms ahead, every joint
    if ((now - t0) % std::chrono::milliseconds(10) != Duration(0)) return false;
    for (int j = 0; j < kJoints; ++j) {
      const TimePoint at = now + std::chrono::milliseconds(100);
      busy.daemon().Submit(ManualDaemon::Waypoint(++id, j, at, wave(j, at), Interpolation::kQuintic));
    }
    return true;
  };
  // Warm up: every joint has had a trajectory, every buffer its size.
  for (; t < t0 + std::chrono::seconds(1); t += std::chrono::milliseconds(1)) {
    stream(t);
    busy.RunTo(t);
    idle.RunTo(t);
  }
  const auto measure = [](Cost& c, bool arrival, auto&& once) {
    const long a0 = g_mallocs;
    const auto w0 = WallClock::now();
    once();
    const double us = std::chrono::duration<double, std::micro>(WallClock::now() - w0).count();
    (arrival ? c.arrival_allocations : c.plain_allocations) += g_mallocs - a0;
    (arrival ? c.arrival_us : c.plain_us).push_back(us);
    c.sum_us += us;
    ++c.periods;
  };
  // The three interleaved, period by period, so the shared machine's load hits them alike.
  for (int k = 0; k < rounds * kPeriods; ++k, t += std::chrono::milliseconds(1)) {
    const bool arrival = stream(t);
    busy.clock().Set(t);
    idle.clock().Set(t);
    measure(c_busy, arrival, [&] { busy.daemon().RunOnce(t); });
    measure(c_idle, false, [&] { idle.daemon().RunOnce(t); });
    measure(c_bare, false, [&] {
      bare.Update(t, done);
      bare.ReadState(bare_state);
    });
    busy.Drain();  // the ServerDaemon's side: not timed
    idle.Drain();
  }
  std::printf(
      "| per 1 ms period (%d periods, manual clock, interleaved) | median µs | p99 µs | median, %% of 1 ms "
      "| allocations per period |\n|---|---|---|---|---|\n",
      rounds * kPeriods);
  const auto row = [](const std::string& what, const std::vector<double>& us, long allocations) {
    const double med = Percentile(us, 0.5);
    std::printf("| %s | %.2f | %.2f | %.3f %% | %.2f |\n", what.c_str(), med, Percentile(us, 0.99),
                med / 10.0,
                static_cast<double>(allocations) / static_cast<double>(std::max<std::size_t>(us.size(), 1)));
  };
  row("floor: bare loop, KinematicDriver Update + ReadState, 31 dofs", c_bare.plain_us,
      c_bare.plain_allocations);
  row("RobotDaemon::RunOnce, 31 dofs, no trajectory", c_idle.plain_us, c_idle.plain_allocations);
  row("RobotDaemon::RunOnce, 31 dofs interpolating (quintic), periods without arrivals", c_busy.plain_us,
      c_busy.plain_allocations);
  row("same, periods in which 31 waypoints arrived (1 in 10: a 100 Hz delay-mode client)", c_busy.arrival_us,
      c_busy.arrival_allocations);
  std::printf(
      "\nmean per period over all periods: interpolating %.2f µs (%.2f %% of 1 ms), idle daemon %.2f µs, "
      "bare loop %.2f µs; interpolating / idle %.1f×\n",
      c_busy.sum_us / static_cast<double>(c_busy.periods),
      c_busy.sum_us / static_cast<double>(c_busy.periods) / 10.0,
      c_idle.sum_us / static_cast<double>(c_idle.periods),
      c_bare.sum_us / static_cast<double>(c_bare.periods), c_busy.sum_us / c_idle.sum_us);
}

// Where the arrival periods' allocations are: the TrajectoryTracker alone,
// one quintic waypoint appended to a running trajectory (as a 100 Hz stream
// does), then one Sample() of it.
void TrackerAllocations() {
  const RobotModel model = Chain(1);
  TrajectoryTracker tracker(model, TrackerOptions{.period = std::chrono::milliseconds(1)});
  RobotState state;
  state.position = state.velocity = state.effort = Eigen::VectorXd::Zero(1);
  std::vector<TrajectoryTracker::Answer> answers;
  std::vector<TrajectoryTracker::Started> started;
  answers.reserve(64);
  started.reserve(64);
  const TimePoint t0 = ManualDaemon::Origin();
  long add_allocations = 0, sample_allocations = 0;
  std::vector<double> add_us;
  int n = 0;
  for (int k = 0; k < 2000; ++k) {
    const TimePoint now = t0 + k * std::chrono::milliseconds(10);
    const TimePoint at = now + std::chrono::milliseconds(100);
    const QueuedItem w = ManualDaemon::Waypoint(static_cast<CommandId>(k + 1), 0, at,
                                                0.5 * std::sin(std::numbers::pi * ToSeconds(at - t0)),
                                                Interpolation::kQuintic);
    answers.clear();
    const long a0 = g_mallocs;
    const auto w0 = WallClock::now();
    tracker.Add({&w, 1}, now, state, answers, started);
    const double us = std::chrono::duration<double, std::micro>(WallClock::now() - w0).count();
    const long a1 = g_mallocs;
    tracker.Sample(now, answers);
    const long a2 = g_mallocs;
    if (k >= 1000) {  // warmed up: past the knot bound (Forget), every buffer its size
      add_allocations += a1 - a0;
      sample_allocations += a2 - a1;
      add_us.push_back(us);
      ++n;
    }
  }
  std::printf(
      "\nTrajectoryTracker alone (1 joint, quintic, a 100 Hz stream 100 ms ahead, %d waypoints after 1,000 "
      "of warm-up): Add() of one waypoint %.1f allocations, median %.2f µs; Sample() %.2f allocations\n",
      n, static_cast<double>(add_allocations) / n, Percentile(add_us, 0.5),
      static_cast<double>(sample_allocations) / n);
}

}  // namespace

int main(int argc, char** argv) {
  std::string shared = "../shared/robots", csv;
  bool quick = false, cost_only = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--csv") == 0 && i + 1 < argc) {
      csv = argv[++i];
    } else if (std::strcmp(argv[i], "--quick") == 0) {
      quick = true;
    } else if (std::strcmp(argv[i], "--cost-only") == 0) {
      cost_only = true;
    } else {
      shared = argv[i];
    }
  }
  const std::string urdf = shared + "/iiwa14.urdf";
  if (cost_only) {
    std::printf("(a), (b): not measured (--cost-only)\n");
  } else if (std::ifstream(urdf).good()) {
    std::printf(
        "(a) iiwa14 '%s', 0.5 Hz 0.5 rad sine, delay mode 300 ms, 6 s of frames; measured position against "
        "the continuous sine every control period (kinematic: 1 ms; ode: 10 ms, its default), from the first "
        "start time + 1 s to the last frame "
        "(answers: SUCCESS/MODIFIED/other):\n\n",
        kJoint);
    SineTable(urdf, csv);
    std::printf("\n(b) ");
    RecedingHorizon(urdf, quick ? 1000 : 10000);
  } else {
    std::printf("(a), (b): %s not found; not measured\n", urdf.c_str());
  }
  std::printf("\n(c) the RobotDaemon's cost per period:\n\n");
  DaemonCost(quick ? 3 : 20);
  TrackerAllocations();
  return 0;
}

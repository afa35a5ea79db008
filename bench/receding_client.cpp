// Issue 22's receding-horizon client through the network (not a test;
// run_bench.py's 'trajectory' figure runs it through robotalk-lcm-relay with
// 5 ms ± 3 ms of latency on the client → server leg): every 10 ms a 200 ms
// quintic trajectory (20 points, 10 ms apart) starting 20 ms ahead of the
// synchronised server clock, on one joint, with RobotClient::SendTrajectory.
// The server's kinematic driver follows the reference exactly, so the STATE
// stream (5 ms, twice per 10 ms period) carries it: the largest velocity step
// between consecutive references, freezes (a reference held longer than one
// and a half periods) and missing samples, from the first second on. One
// line of text.
// The last lines repeat the figures as key=value for tests
// (tests/integration/receding_relay_test.sh).
//   robotalk-receding-client --url URL --robot NAME --joint NAME [--splices N]
//       [--freeze-ms MS (15)] [--min-speed RAD_S (0.5): the acceleration estimate's |v0 + v1| floor]
#include "bench_util.h"
#include "robotalk/robot_client.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <numbers>
#include <sstream>
#include <string>
#include <thread>

using namespace robotalk;
using namespace robotalk::bench;

int main(int argc, char** argv) {
  try {
    const Args a(argc, argv, 1);
    ClientOptions o;
    o.lcm_url = a.Str("url", "");
    RobotClient c(o);
    c.Connect(a.Str("robot", "iiwa"));
    const std::string joint = a.Str("joint", "iiwa_joint_6");
    const int splices = static_cast<int>(a.Num("splices", 10000));
    const Duration freeze = FromSeconds(a.Num("freeze-ms", 15) / 1e3);
    const double min_speed = a.Num("min-speed", 0.5);
    const int dof = c.model().dof_offset(c.model().JointIndex(joint));
    const TimePoint t0 = c.ServerNow() + std::chrono::milliseconds(50);
    const auto target = [&](TimePoint t) { return 0.5 * std::sin(std::numbers::pi * ToSeconds(t - t0)); };

    // The STATE stream at twice the control rate: a sample sees each period's
    // reference at least once, so consecutive distinct references are
    // consecutive periods (unless the server ran a period late).
    std::mutex m;
    double max_dv = 0, last_v = NAN, last_p = NAN;
    TimePoint changed{};
    Duration max_dv_after{0};  // server time between the first samples of the two references
    // The kinematic driver's state is its reference, which moves by the mean
    // of its velocities over the period (exactly when the tracker limits it,
    // to within a·dt²/12 on the plan): dt = 2·Δp / (v0 + v1) gives the
    // period the server actually ran, and Δv / dt the acceleration, to check
    // against the limit whatever the period (away from turns, |v0 + v1| > 0.5).
    double max_accel = 0, max_accel_dv = 0, max_accel_dt = 0;
    std::int64_t last_sample = -1;
    long frozen = 0, missing = 0, samples = 0, references = 0;
    bool in_freeze = false;
    c.StartStateStream(std::chrono::milliseconds(5), [&](const StateSample& s) {
      std::lock_guard lock(m);
      if (s.server_time < t0 + std::chrono::seconds(1)) return;  // from rest onto the sine
      const double p = s.positions[static_cast<std::size_t>(dof)],
                   v = s.velocities[static_cast<std::size_t>(dof)];
      if (last_sample >= 0 && s.sample != last_sample + 1) missing += s.sample - last_sample - 1;
      last_sample = s.sample;
      ++samples;
      if (p == last_p) {  // the same reference: a freeze once it outlives one and a half periods
        if (!in_freeze && s.server_time - changed > freeze) {
          ++frozen;
          in_freeze = true;
        }
        return;
      }
      if (!std::isnan(last_v) && std::abs(v - last_v) > max_dv) {
        max_dv = std::abs(v - last_v);
        max_dv_after = s.server_time - changed;
      }
      if (!std::isnan(last_v) && std::abs(v + last_v) > min_speed) {
        const double dt = 2 * (p - last_p) / (v + last_v);
        if (dt > 0 && std::abs(v - last_v) / dt > max_accel) {
          max_accel = std::abs(v - last_v) / dt;
          max_accel_dv = std::abs(v - last_v);
          max_accel_dt = dt;
        }
      }
      ++references;
      in_freeze = false;
      changed = s.server_time;
      last_v = v;
      last_p = p;
    });
    TrajectoryOptions options;
    options.mode = CommandMode::kDelay;
    options.interpolation = Interpolation::kQuintic;
    const auto wall0 = std::chrono::steady_clock::now();
    long sent = 0;
    for (int i = 0; i < splices; ++i) {
      std::this_thread::sleep_until(wall0 + i * std::chrono::milliseconds(10));
      const TimePoint now = c.ServerNow();
      JointTrajectory tr{.joint = joint, .points = {}};
      for (int k = 0; k < 20; ++k) {
        const Duration offset = std::chrono::milliseconds(20 + 10 * k);
        tr.points.push_back(TrajectoryPoint{.time_from_start = offset, .positions = {target(now + offset)}});
      }
      options.start = now;
      c.SendTrajectory(tr,
                       options);  // the replies are not waited for (SUCCESS, or INTERRUPTED when replaced)
      sent += 20;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    c.StopStateStream();
    // The server's own figure: the largest velocity change of any reference
    // over the period it actually ran (SERVER_COUNTERS).
    double server_accel = NAN;
    {
      const Reply r = c.ServerCounters();
      std::istringstream names(r.message);
      std::string name;
      for (std::size_t i = 0; names >> name && i < r.values.size(); ++i)
        if (name == "reference_max_acceleration") server_accel = r.values[i];
    }
    std::lock_guard lock(m);
    std::printf(
        "through robotalk-lcm-relay: %d splices (%ld points); STATE at 5 ms, %ld samples, %ld distinct "
        "references "
        "from the first second on: largest velocity step between consecutive references %.4f rad/s (their "
        "first "
        "samples %.1f ms apart); freezes "
        "(a reference held > %.0f ms) %ld; missing samples %ld; largest acceleration between consecutive "
        "references over the period the server ran (2·Δp / (v0 + v1), where |v0 + v1| > %.2g rad/s) %.2f "
        "rad/s² (a step of %.4f rad/s over %.2f ms); the server's own largest |Δv| / (its period) of any "
        "reference: %.4f rad/s²\n",
        splices, sent, samples, references, max_dv, 1e3 * ToSeconds(max_dv_after), 1e3 * ToSeconds(freeze),
        frozen, missing, min_speed, max_accel, max_accel_dv, 1e3 * max_accel_dt, server_accel);
    std::printf(
        "references=%ld\nmax_step=%.6f\nmax_acceleration=%.4f\nserver_max_acceleration=%.6f\nfreezes=%ld\n"
        "missing=%ld\n",
        references, max_dv, max_accel, server_accel, frozen, missing);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robotalk-receding-client: %s\n", e.what());
    return 1;
  }
}

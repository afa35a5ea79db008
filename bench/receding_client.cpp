// Issue 22's receding-horizon client through the network (not a test;
// run_bench.py's 'trajectory' figure runs it through robotalk-lcm-relay with
// 5 ms ± 3 ms of latency on the client → server leg): every 10 ms a 200 ms
// quintic trajectory (20 points, 10 ms apart) starting 20 ms ahead of the
// synchronised server clock, on one joint, with RobotClient::SendTrajectory.
// The server's kinematic driver follows the reference exactly, so the STATE
// stream (10 ms) carries it: the largest velocity step between consecutive
// samples, freezes (a sample with the previous one's position) and missing
// samples, from the first second on. One line of text.
//   robotalk-receding-client --url URL --robot NAME --joint NAME [--splices N]
#include "bench_util.h"
#include "robotalk/robot_client.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <numbers>
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
    const int dof = c.model().dof_offset(c.model().JointIndex(joint));
    const TimePoint t0 = c.ServerNow() + std::chrono::milliseconds(50);
    const auto target = [&](TimePoint t) { return 0.5 * std::sin(std::numbers::pi * ToSeconds(t - t0)); };

    std::mutex m;
    double max_dv = 0, last_v = NAN, last_p = NAN;
    std::int64_t last_sample = -1;
    long frozen = 0, missing = 0, samples = 0;
    c.StartStateStream(std::chrono::milliseconds(10), [&](const StateSample& s) {
      std::lock_guard lock(m);
      if (s.server_time < t0 + std::chrono::seconds(1)) return;  // from rest onto the sine
      const double p = s.positions[static_cast<std::size_t>(dof)],
                   v = s.velocities[static_cast<std::size_t>(dof)];
      if (last_sample >= 0 && s.sample != last_sample + 1) missing += s.sample - last_sample - 1;
      if (last_sample >= 0 && s.sample == last_sample + 1) {
        max_dv = std::max(max_dv, std::abs(v - last_v));
        if (p == last_p) ++frozen;
      }
      last_sample = s.sample;
      last_v = v;
      last_p = p;
      ++samples;
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
    std::lock_guard lock(m);
    std::printf(
        "through robotalk-lcm-relay: %d splices (%ld points), STATE samples %ld from the first second on: "
        "largest velocity step between consecutive samples %.4f rad/s; freezes %ld; missing samples %ld\n",
        splices, sent, samples, max_dv, frozen, missing);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "robotalk-receding-client: %s\n", e.what());
    return 1;
  }
}

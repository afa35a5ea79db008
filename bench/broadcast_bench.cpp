// What signing a keyed server's STATE stream costs (docs/security.md, "Cost"):
// the pioneer's state sample published at 1 kHz on real LCM, every other
// sample signed (so both kinds share the run and the machine's load), the
// thread CPU time of each publish measured; then a client's verification.
//   scripts/netns_run.sh robotalk-bench-broadcast MODELS_DIR [SAMPLES]
// Prints, per kind: median and p99 CPU time per sample (µs), and the share
// of one core at 1 kHz.
#include "robotalk/broadcast_signature.h"
#include "robotalk/channels.h"
#include "robotalk/request.h"
#include "robotalk/routed_lcm_transport.h"
#include "robotalk/urdf_import.h"

#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

namespace {

using namespace robotalk;

double ThreadCpuMicros() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e6 + static_cast<double>(ts.tv_nsec) / 1e3;
}

void Report(const char* what, std::vector<double> us) {
  std::sort(us.begin(), us.end());
  const double median = us[us.size() / 2], p99 = us[us.size() * 99 / 100];
  std::printf("%-34s median %7.2f us  p99 %7.2f us  at 1 kHz: %5.2f %% of a core\n", what, median, p99,
              median * 1000 / 1e6 * 100);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: robotalk-bench-broadcast MODELS_DIR [SAMPLES]\n");
    return 2;
  }
  const int samples = argc > 2 ? std::atoi(argv[2]) : 5000;
  const RobotModel model =
      LoadUrdfFile(std::string(argv[1]) + "/pioneer2dx_pantilt.urdf", {.robot_name = "pioneer"}).model;
  auto lan = OpenLcmTransport("udpm://239.255.76.67:7690?ttl=0");
  const KeyPair server = KeyPair::Generate();
  const Nonce instance = RandomNonce();
  const BroadcastSigner signer(server, instance);
  const std::string channel = StateChannel("pioneer");
  StateSample s;
  s.robot = "pioneer";
  s.period = std::chrono::milliseconds(1);
  s.positions.assign(static_cast<std::size_t>(model.num_dofs()), 0.1);
  s.velocities = s.efforts = s.positions;
  s.frame_poses.assign(model.frames().size(), PoseValues{0, 0, 0, 1, 0, 0, 0});
  std::vector<double> plain, signed_us, sign_only;
  std::vector<std::uint8_t> last_signed;
  auto next = std::chrono::steady_clock::now();
  for (int i = 0; i < samples; ++i) {
    next += std::chrono::milliseconds(1);
    std::this_thread::sleep_until(next);
    s.sample = i + 1;
    s.server_time = TimePoint(std::chrono::steady_clock::now().time_since_epoch());
    const bool sign = i % 2 == 1;
    const double t0 = ThreadCpuMicros();
    std::vector<std::uint8_t> bytes = EncodeStateSample(s);
    double t1 = t0;
    if (sign) {
      t1 = ThreadCpuMicros();
      signer.Sign(channel, bytes);
      sign_only.push_back(ThreadCpuMicros() - t1);
    }
    lan->Publish(channel, bytes);
    (sign ? signed_us : plain).push_back(ThreadCpuMicros() - t0);
    if (sign) last_signed = bytes;
  }
  std::printf("STATE of '%s' (%d dofs, %zu frames): %zu bytes unsigned, %zu signed; %d samples at 1 kHz\n",
              model.name().c_str(), model.num_dofs(), model.frames().size(), EncodeStateSample(s).size(),
              last_signed.size(), samples);
  Report("publish, unsigned (encode + send)", plain);
  Report("publish, signed (encode+sign+send)", signed_us);
  Report("  of which the Ed25519 signature", sign_only);
  std::vector<double> verify;
  for (int i = 0; i < 2000; ++i) {
    const double t0 = ThreadCpuMicros();
    if (VerifyBroadcast(channel, last_signed, server.public_key, &instance) != BroadcastVerdict::kAuthentic) {
      return 1;
    }
    verify.push_back(ThreadCpuMicros() - t0);
  }
  Report("client: verify one sample", verify);
  return 0;
}

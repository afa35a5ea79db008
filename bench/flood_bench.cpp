// Google Benchmark of what a flood of packages naming made-up sessions costs
// the ServerDaemon thread, per package, on the in-memory bus (no kernel: the
// server's own work only): open mode (an unsigned SESSION_UNKNOWN answer),
// keyed mode with every answer signed (the tenth session's server), and keyed
// mode past the signed answers' budget (ServerDaemonOptions::
// unknown_answers_per_second: counted, not answered). The floor beside them:
// decoding the same package alone. Figures: docs/security.md, "Cost".
//   robotalk-flood-bench [--benchmark_format=json ...]
#include "robot_daemon.h"
#include "robotalk/channels.h"
#include "robotalk/memory_transport.h"
#include "robotalk/request.h"
#include "robotalk/robot_model.h"
#include "server_daemon.h"

#include "kinematic_driver.h"

#include "bench_keys.h"

#include <benchmark/benchmark.h>

#include <memory>
#include <vector>

namespace {

using namespace robotalk;

using bench::Identity;

RobotModel Pan() {
  RobotModelBuilder b("pan");
  b.AddLink(Link{.name = "base"}).AddLink(Link{.name = "head"});
  Joint pan{.name = "pan", .servo_types = ServoType::kSetPoint};
  pan.dofs = {Dof{.axis = Eigen::Vector3d::UnitZ(), .limits = {.lower = -2, .upper = 2, .velocity = 2}}};
  b.AddJoint(pan, "base", "head");
  b.SetRoot("base", Pose{}, BaseType::kFixed);
  return b.Build();
}

// A package as a flood sends it: a made-up client and session, one set-point.
std::vector<std::uint8_t> Forged(std::int64_t i) {
  Request r{.client_id = 0xBAD0000 + i, .session_id = 1'000'000 + i, .sequence = 1};
  r.commands.push_back(Command{1, CommandType::kJointSetPoint, std::nullopt, "pan", {0.5}});
  return EncodeRequest(r);
}

enum Mode { kOpen = 0, kKeyedSigned = 1, kKeyedPastBudget = 2 };

void BM_UnknownSessionFlood(benchmark::State& state) {
  const auto mode = static_cast<Mode>(state.range(0));
  ManualClock clock;
  auto bus = std::make_shared<MemoryBus>();
  MemoryTransport server_side{bus};
  MemoryTransport flooder{bus};
  ServerDaemonOptions options;
  if (mode != kOpen) {
    options.sessions.identity = std::make_shared<const KeyPair>(Identity(1));
    options.sessions.access = std::make_shared<const AccessList>(
        AccessList::Parse(Identity(2).public_key.ToString() + " alice *=all\n", "bench"));
    // Every answer signed: a budget no flood reaches; past it: none left.
    options.unknown_answers_per_second = mode == kKeyedSigned ? 1'000'000'000 : 1;
  }
  RobotDaemon robot("bot", "kinematic", std::make_unique<KinematicDriver>(Pan()), clock);
  ServerDaemon server(server_side, clock, options);
  server.AddRobot(robot, SessionOptions{});
  std::vector<std::vector<std::uint8_t>> packages;
  for (int i = 0; i < 4096; ++i) packages.push_back(Forged(i));
  std::size_t next = 0;
  for (auto _ : state) {
    flooder.Publish(RequestChannel("bot"), packages[next++ % packages.size()]);
    server.RunOnce(Duration(0));
  }
  state.counters["unanswered"] = static_cast<double>(server.unknown_unanswered());
  state.SetLabel(mode == kOpen          ? "open"
                 : mode == kKeyedSigned ? "keyed, every answer signed"
                                        : "keyed, past the budget");
}
BENCHMARK(BM_UnknownSessionFlood)->Arg(kOpen)->Arg(kKeyedSigned)->Arg(kKeyedPastBudget);

// The floor: the same package decoded, nothing else.
void BM_DecodeFloodPackage(benchmark::State& state) {
  const std::vector<std::uint8_t> bytes = Forged(1);
  for (auto _ : state) benchmark::DoNotOptimize(DecodeRequest(bytes));
}
BENCHMARK(BM_DecodeFloodPackage);

}  // namespace

BENCHMARK_MAIN();

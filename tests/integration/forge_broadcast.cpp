// forge_broadcast: anyone on the LAN, for server_identity_test.sh (issue 19).
//   forge_broadcast URL state ROBOT DOFS N
//       N forged STATE samples of ROBOT (base 42 42, q 1.234), each sent twice:
//       unsigned, and signed by a key of the forger's own; 10 ms apart.
//   forge_broadcast URL announce ROBOT N
//       N ANNOUNCEs naming ROBOT, by server 0000000000000001 "serving it for a year".
//   forge_broadcast URL announce-names PREFIX N ROUNDS
//       ROUNDS times, 0.5 s apart: N ANNOUNCEs, one datagram each, naming
//       PREFIX-0 .. PREFIX-(N-1) (no server behind them).
//   forge_broadcast URL replay-announce ROBOT RECORD_S REPLAY_S
//       records the ANNOUNCEs naming ROBOT for RECORD_S seconds (a keyed
//       server's, signed), then sends them again, every 10 ms, for REPLAY_S.
//   forge_broadcast URL refuse-hellos ROBOT SECONDS TEXT
//       for SECONDS, answers every open-mode HELLO for ROBOT with a refusal
//       whose reason is TEXT (no server behind it).
#include "robotalk/broadcast_signature.h"
#include "robotalk/channels.h"
#include "robotalk/request.h"
#include "robotalk/routed_lcm_transport.h"

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

int main(int argc, char** argv) {
  using namespace robotalk;
  if (argc < 5) {
    std::fprintf(stderr, "usage: forge_broadcast URL state ROBOT DOFS N | URL announce ROBOT N\n");
    return 2;
  }
  const std::string url = argv[1], what = argv[2], robot = argv[3];
  auto lan = OpenLcmTransport(url);
  if (what == "state" && argc == 6) {
    const int dofs = std::atoi(argv[4]), n = std::atoi(argv[5]);
    const KeyPair mallory = KeyPair::Generate();
    for (int i = 0; i < n; ++i) {
      StateSample s;
      s.robot = robot;
      s.server_time = TimePoint(std::chrono::hours(10000) + std::chrono::milliseconds(i));
      s.sample = 1000 + i;
      s.base.x = s.base.y = 42;
      s.positions.assign(static_cast<std::size_t>(dofs), 1.234);
      s.velocities.assign(static_cast<std::size_t>(dofs), 0.0);
      s.efforts.assign(static_cast<std::size_t>(dofs), 0.0);
      std::vector<std::uint8_t> bytes = EncodeStateSample(s);
      lan->Publish(StateChannel(robot), bytes);
      BroadcastSigner(mallory, Nonce{}).Sign(StateChannel(robot), bytes);
      lan->Publish(StateChannel(robot), bytes);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return 0;
  }
  if (what == "announce") {
    const int n = std::atoi(argv[4]);
    for (int i = 0; i < n; ++i) {
      Announcement a;
      a.server_id = 1;
      a.server_time = TimePoint(std::chrono::hours(1000));
      a.uptime = std::chrono::hours(24 * 365);
      a.url_hint = "forged";
      a.robots.push_back({robot, "kinematic", 1, 1, BaseType::kFixed, false, 0});
      lan->Publish(kAnnounceChannel, EncodeAnnouncement(a));
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return 0;
  }
  if (what == "announce-names" && argc == 6) {
    const int n = std::atoi(argv[4]), rounds = std::atoi(argv[5]);
    for (int round = 0; round < rounds; ++round) {
      for (int i = 0; i < n; ++i) {
        Announcement a;
        a.server_id = 1000 + i;
        a.server_time = TimePoint(std::chrono::hours(1000));
        a.uptime = std::chrono::hours(1);
        a.robots.push_back(
            {robot + "-" + std::to_string(i), "kinematic", 1, 1, BaseType::kDifferential, false, 0});
        lan->Publish(kAnnounceChannel, EncodeAnnouncement(a));
        if (i % 50 == 49) std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
    return 0;
  }
  if (what == "replay-announce" && argc == 6) {
    using Seconds = std::chrono::duration<double>;
    const auto record = std::chrono::steady_clock::now() + Seconds(std::atof(argv[4]));
    std::vector<std::vector<std::uint8_t>> recorded;
    auto sub = lan->Subscribe(kAnnounceChannel, [&](const std::string&, std::span<const std::uint8_t> bytes) {
      try {
        for (const RobotAnnouncement& r : DecodeAnnouncement(bytes).robots)
          if (r.name == robot) recorded.emplace_back(bytes.begin(), bytes.end());
      } catch (const ProtocolError&) {
      }
    });
    while (std::chrono::steady_clock::now() < record) lan->HandleFor(std::chrono::milliseconds(20));
    sub.reset();
    std::fprintf(stderr, "forge_broadcast: recorded %zu announcements of %s\n", recorded.size(),
                 robot.c_str());
    if (recorded.empty()) return 1;
    const auto replay = std::chrono::steady_clock::now() + Seconds(std::atof(argv[5]));
    for (std::size_t i = 0; std::chrono::steady_clock::now() < replay; ++i) {
      lan->Publish(kAnnounceChannel, recorded[i % recorded.size()]);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return 0;
  }
  if (what == "refuse-hellos" && argc == 6) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(std::atof(argv[4]));
    const std::string text = argv[5];
    auto sub =
        lan->Subscribe(HelloChannel(robot), [&](const std::string&, std::span<const std::uint8_t> bytes) {
          try {
            const Hello hello = DecodeHello(bytes);
            HelloAnswer answer{.server_id = 1, .session_id = 0, .refusal = text};
            answer.body.client_id = hello.body.client_id;
            answer.body.client_nonce = hello.body.client_nonce;
            lan->Publish(HelloAnswerChannel(robot, hello.body.client_id), EncodeHelloAnswer(answer));
          } catch (const ProtocolError&) {
          }
        });
    while (std::chrono::steady_clock::now() < until) lan->HandleFor(std::chrono::milliseconds(20));
    return 0;
  }
  std::fprintf(stderr, "forge_broadcast: unknown '%s'\n", what.c_str());
  return 2;
}

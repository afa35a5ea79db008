// Google Benchmark of the protocol codec (protocol_codec.h) and the
// configuration codec (config_codec.h), private headers of the protocol
// library: what every package costs a client and the server in CPU before
// the network. Figures:
// docs/performance.md, "In-process".
//   robotalk-codec-bench [--benchmark_format=json ...]
#include "config_codec.h"
#include "protocol_codec.h"
#include "robotalk/urdf_import.h"

#include <benchmark/benchmark.h>

#include <vector>

namespace {

using robotalk::Command;
using robotalk::CommandType;

// A package of `n` JOINT_SETPOINT commands, as a client sends it.
robotalk_msgs::package_t Package(int n) {
  robotalk_msgs::package_t p{};
  p.header.protocol_version = robotalk::kProtocolVersion;
  p.header.client_id = 0x1234;
  p.header.sequence = 1;
  p.header.payload_type = robotalk_msgs::package_header_t::PAYLOAD_COMMANDS;
  p.header.payload_size = n;
  p.header.mode = robotalk_msgs::package_header_t::MODE_DELAY;
  for (int i = 0; i < n; ++i) {
    const Command c{.id = i + 1,
                    .type = CommandType::kJointSetPoint,
                    .start_time = robotalk::FromWireMicros(1000000 + i * 1000),
                    .target = "pan",
                    .values = {0.25}};
    p.commands.push_back(robotalk::ToWire(c));
  }
  p.num_commands = n;
  return p;
}

std::vector<std::uint8_t> Encode(const auto& msg) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

void BM_EncodePackage(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::vector<std::uint8_t> bytes(65536);
  for (auto _ : state) {
    const robotalk_msgs::package_t p = Package(n);  // ToWire of every command, as the client does
    benchmark::DoNotOptimize(p.encode(bytes.data(), 0, static_cast<int>(bytes.size())));
  }
  state.SetItemsProcessed(state.iterations() * n);
}

void BM_DecodePackage(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::vector<std::uint8_t> bytes = Encode(Package(n));
  for (auto _ : state) {
    const robotalk_msgs::package_t p = robotalk::DecodePackage(bytes);  // bounds-checked, as the server does
    for (const auto& c : p.commands) benchmark::DoNotOptimize(robotalk::FromWire(c).values.data());
  }
  state.SetItemsProcessed(state.iterations() * n);
  state.SetLabel(std::to_string(bytes.size()) + " bytes");
}

robotalk_msgs::reply_package_t ReplyPackage(int n) {
  robotalk_msgs::reply_package_t r{};
  r.protocol_version = robotalk::kProtocolVersion;
  r.client_id = 0x1234;
  r.ack_sequence = 1;
  for (int i = 0; i < n; ++i) {
    robotalk::Reply rep{.id = i + 1, .values = {1, 2, 0.5, 0, 0}};  // a BASE_POSE answer
    r.replies.push_back(robotalk::ToWire(rep));
  }
  r.num_replies = n;
  return r;
}

void BM_DecodeReplyPackage(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::vector<std::uint8_t> bytes = Encode(ReplyPackage(n));
  for (auto _ : state) {
    const robotalk_msgs::reply_package_t r = robotalk::DecodeReplyPackage(bytes);
    for (const auto& rep : r.replies) benchmark::DoNotOptimize(robotalk::FromWire(rep).values.data());
  }
  state.SetItemsProcessed(state.iterations() * n);
  state.SetLabel(std::to_string(bytes.size()) + " bytes");
}

const robotalk::RobotModel& Pioneer() {
  static const robotalk::RobotModel m =
      robotalk::LoadUrdfFile(ROBOTALK_BENCH_MODELS "/pioneer2dx_pantilt.urdf").model;
  return m;
}

void BM_EncodeConfig(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(robotalk::EncodeConfig(Pioneer()).data());
  state.SetLabel("pioneer2dx_pantilt");
}

void BM_DecodeConfig(benchmark::State& state) {
  const std::vector<std::uint8_t> bytes = robotalk::EncodeConfig(Pioneer());
  for (auto _ : state) benchmark::DoNotOptimize(robotalk::DecodeConfig(bytes).num_dofs());
  state.SetLabel("pioneer2dx_pantilt, " + std::to_string(bytes.size()) + " bytes");
}

}  // namespace

BENCHMARK(BM_EncodePackage)->Arg(1)->Arg(10)->Arg(100);
BENCHMARK(BM_DecodePackage)->Arg(1)->Arg(10)->Arg(100);
BENCHMARK(BM_DecodeReplyPackage)->Arg(1)->Arg(10);
BENCHMARK(BM_EncodeConfig);
BENCHMARK(BM_DecodeConfig);
BENCHMARK_MAIN();

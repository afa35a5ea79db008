// robotalk-fuzz-seeds OUT_DIR [FILE.urdf ...]: writes a seed corpus per fuzz
// target into OUT_DIR/<target>/, all valid messages as the server and the
// client send them (scripts/fuzz.sh runs it before fuzzing), and the given
// URDF files, each also as its configuration message.
#include "config_codec.h"
#include "protocol_codec.h"
#include "robotalk/error.h"
#include "robotalk/request.h"
#include "robotalk/urdf_import.h"
#include "robotalk_msgs/announce_t.hpp"
#include "robotalk_msgs/package_t.hpp"
#include "robotalk_msgs/reply_package_t.hpp"
#include "robotalk_msgs/robot_state_t.hpp"

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
namespace msgs = robotalk_msgs;

void Write(const fs::path& dir, const std::string& name, const std::vector<std::uint8_t>& bytes) {
  fs::create_directories(dir);
  std::ofstream(dir / name, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

template <typename Msg>
std::vector<std::uint8_t> Encode(const Msg& m) {
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

msgs::package_header_t Header(std::int64_t sequence, std::int8_t type, std::int32_t size, std::int8_t mode) {
  msgs::package_header_t h{};
  h.protocol_version = robotalk::kProtocolVersion;
  h.client_id = 0x1234abcd;
  h.sequence = sequence;
  h.send_time_us = 1'000'000 * sequence;
  h.payload_type = type;
  h.payload_size = size;
  h.mode = mode;
  if (mode == msgs::package_header_t::MODE_PLAYBACK) {
    h.playback_id = 7;
    h.playback_frames = 10;
    h.playback_duration_us = 900'000;
  }
  return h;
}

void Packages(const fs::path& dir) {
  using H = msgs::package_header_t;
  int n = 0;
  for (std::int8_t type = 1; type <= 8; ++type) {
    msgs::package_t p{};
    msgs::query_t q{};
    q.id = type;
    q.type = type;
    q.target = type == 2 ? "pan" : "";
    q.period_us = type == 7 ? 100'000 : 0;
    p.queries = {q};
    p.num_queries = 1;
    p.header = Header(type, H::PAYLOAD_QUERIES, 1, H::MODE_DIRECT);
    Write(dir, "query_" + std::to_string(n++), Encode(p));
  }
  const std::vector<std::pair<std::string, std::vector<double>>> args = {
      {"pan", {0.5}},  {"pan", {0.1}},   {"pan", {2.0}}, {"camera", {1, 0, 0.5, 1, 0, 0, 0}},
      {"", {1, 0, 0}}, {"", {0.2, 0.1}}, {"", {}},       {"", {}}};
  for (std::int8_t mode = 0; mode <= 2; ++mode) {
    msgs::package_t p{};
    for (std::int8_t type = 1; type <= 8; ++type) {
      msgs::command_t c{};
      c.id = 100 + type;
      c.type = type;
      c.start_time_us = mode == H::MODE_DIRECT ? 0 : 100'000 * type;
      c.target = args[static_cast<std::size_t>(type - 1)].first;
      c.values = args[static_cast<std::size_t>(type - 1)].second;
      c.num_values = static_cast<std::int16_t>(c.values.size());
      p.commands.push_back(c);
    }
    p.num_commands = static_cast<std::int32_t>(p.commands.size());
    p.header = Header(10 + mode, H::PAYLOAD_COMMANDS, p.num_commands, mode);
    Write(dir, "commands_mode" + std::to_string(mode), Encode(p));
  }
  msgs::package_t panic{};
  panic.header = Header(20, H::PAYLOAD_COMMANDS, 0, H::MODE_DIRECT);
  panic.header.panic = 1;
  Write(dir, "panic", Encode(panic));
}

void Replies(const fs::path& dir) {
  msgs::reply_package_t p{};
  p.protocol_version = robotalk::kProtocolVersion;
  p.client_id = 0x1234abcd;
  p.ack_sequence = 3;
  p.server_receive_us = 5'000'000;
  p.server_send_us = 5'000'100;
  for (std::int8_t signal = 0; signal <= 6; ++signal) {
    msgs::reply_t r{};
    r.id = signal;
    r.signal = signal;
    r.message =
        signal == 0 ? "" : "JOINT_SETPOINT 'tilt': dof 0: 1 rad clamped to the upper limit 0.5411 rad";
    r.exec_time_us = 5'000'000;
    r.values = signal == 0 ? std::vector<double>{0.1, 0.2, 0.3} : std::vector<double>{};
    r.num_values = static_cast<std::int32_t>(r.values.size());
    p.replies.push_back(r);
  }
  p.num_replies = static_cast<std::int32_t>(p.replies.size());
  Write(dir, "replies", Encode(p));
  p.replies.clear();
  p.num_replies = 0;
  Write(dir, "ack_only", Encode(p));
}

void States(const fs::path& dir) {
  msgs::robot_state_t s{};
  s.server_time_us = 1'000'000;
  s.period_us = 100'000;
  s.sample = 1;
  s.robot = "pioneer";
  s.config_hash = 0x55aa;
  s.num_dofs = 2;
  s.position = {0.1, 0.2};
  s.velocity = {0, 0};
  s.effort = {0, 0};
  s.num_frames = 1;
  s.frame_poses = {{0, 0, 0.5, 1, 0, 0, 0}};
  Write(dir, "state", Encode(s));
}

void Announces(const fs::path& dir) {
  msgs::announce_t a{};
  a.protocol_version = robotalk::kProtocolVersion;
  a.server_id = 42;
  a.server_time_us = 1'000'000;
  a.url_hint = "udpm://239.255.76.67:7667?ttl=0";
  for (const char* name : {"pioneer", "arm"}) {
    msgs::robot_info_t r{};
    r.name = name;
    r.driver = "kinematic";
    r.config_hash = 0x55aa;
    r.total_dofs = 2;
    a.robots.push_back(r);
  }
  a.num_robots = 2;
  Write(dir, "announce", Encode(a));
}

}  // namespace

void Hellos(const fs::path& dir) {
  robotalk::Hello open;
  open.body.client_id = 0x1234abcd;
  open.body.client_nonce = robotalk::RandomNonce();
  Write(dir / "hello", "open", robotalk::EncodeHello(open));
  robotalk::ClientHandshake handshake(robotalk::KeyPair::Generate(), 0x1234abcd);
  Write(dir / "hello", "keyed", robotalk::EncodeHello({.keyed = true, .body = handshake.hello()}));
  robotalk::HelloAnswer answer;
  answer.server_id = 42;
  answer.session_id = 77;
  answer.body.client_id = 0x1234abcd;
  Write(dir / "hello_answer", "open", robotalk::EncodeHelloAnswer(answer));
  answer.session_id = 0;
  answer.refusal = "this server runs in keyed mode";
  Write(dir / "hello_answer", "refused", robotalk::EncodeHelloAnswer(answer));
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: robotalk-fuzz-seeds OUT_DIR [FILE.urdf ...]\n";
    return 2;
  }
  const fs::path out = argv[1];
  Packages(out / "package");
  Replies(out / "reply_package");
  States(out / "robot_state");
  Announces(out / "announce");
  Hellos(out);
  for (int i = 2; i < argc; ++i) {
    std::ifstream in(argv[i], std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    const std::string xml = text.str();
    const std::string name = fs::path(argv[i]).stem().string();
    Write(out / "urdf", name, std::vector<std::uint8_t>(xml.begin(), xml.end()));
    try {
      for (bool merge : {false, true}) {
        const auto model = robotalk::ParseUrdf(xml, {.merge_massless_chains = merge}, argv[i]).model;
        Write(out / "config", name + (merge ? "_merged" : ""), robotalk::EncodeConfig(model));
      }
    } catch (const robotalk::Error& e) {
      std::cerr << "robotalk-fuzz-seeds: skipped as a config seed: " << e.what() << "\n";
    }
  }
  return 0;
}

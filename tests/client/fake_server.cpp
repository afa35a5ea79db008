#include "fake_server.h"

#include "robotalk/channels.h"
#include "robotalk/config_codec.h"
#include "robotalk/protocol_codec.h"
#include "robotalk/request.h"
#include "robotalk_msgs/announce_t.hpp"

#include <cstdio>

namespace robotalk::testing {
namespace {

std::string Hex(std::uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

robotalk_msgs::reply_t MakeReply(std::int64_t id, std::int8_t signal, std::string message,
                                 std::int64_t now_us, std::vector<double> values = {}) {
  robotalk_msgs::reply_t r{};
  r.id = id;
  r.signal = signal;
  r.message = std::move(message);
  r.exec_time_us = now_us;
  r.lateness_us = 0;
  r.values = std::move(values);
  r.num_values = static_cast<std::int32_t>(r.values.size());
  return r;
}

}  // namespace

FakeServer::FakeServer(Transport& transport, RobotModel model, FakeServerOptions options)
    : transport_(transport), model_(std::move(model)), options_(options), rng_(options.seed) {
  sub_ = transport_.Subscribe(RequestChannel(model_.name()),
                              [this](const std::string&, std::span<const std::uint8_t> b) { OnRequest(b); });
  hello_sub_ =
      transport_.Subscribe(HelloChannel(model_.name()),
                           [this](const std::string&, std::span<const std::uint8_t> b) { OnHello(b); });
  worker_ = std::thread([this] { Worker(); });
}

void FakeServer::OnHello(std::span<const std::uint8_t> bytes) {
  Hello hello;
  try {
    hello = DecodeHello(bytes);
  } catch (const std::exception&) {
    return;
  }
  HelloAnswer answer;
  {
    std::lock_guard lock(mu_);
    ++hellos_;
    if (options_.mute) return;
    answer.server_id = server_id_;
    answer.session_id = sessions_[hello.body.client_id] = ++next_session_;
    answer.body.client_id = hello.body.client_id;
    answer.body.client_nonce = hello.body.client_nonce;
  }
  transport_.Publish(HelloAnswerChannel(model_.name(), hello.body.client_id), EncodeHelloAnswer(answer));
}

void FakeServer::Restart() {
  std::lock_guard lock(mu_);
  ++server_id_;
  sessions_.clear();
  seen_.clear();
  finals_.clear();
  delayed_.clear();
}

int FakeServer::hellos() const {
  std::lock_guard lock(mu_);
  return hellos_;
}

FakeServer::~FakeServer() {
  stop_ = true;
  worker_.join();
  sub_.reset();
}

std::int64_t FakeServer::ServerNowUs() const {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch() + options_.clock_offset)
      .count();
}

void FakeServer::SetMute(bool mute) {
  std::lock_guard lock(mu_);
  options_.mute = mute;
}

void FakeServer::Announce(std::int64_t server_id) {
  robotalk_msgs::announce_t a{};
  a.protocol_version = kProtocolVersion;
  a.server_id = server_id;
  a.server_time_us = ServerNowUs();
  a.url_hint = "memq://";
  robotalk_msgs::robot_info_t info{};
  info.name = model_.name();
  info.driver = "fake";
  info.config_hash = static_cast<std::int64_t>(ConfigHash(model_));
  info.total_dofs = model_.num_dofs();
  info.panic = panic();
  a.robots.push_back(info);
  a.num_robots = 1;
  Publish(transport_, kAnnounceChannel, a);
}

int FakeServer::executions(std::int64_t id) const {
  std::lock_guard lock(mu_);
  auto it = executions_.find(id);
  return it == executions_.end() ? 0 : it->second;
}
int FakeServer::total_executions() const {
  std::lock_guard lock(mu_);
  int n = 0;
  for (const auto& [id, count] : executions_) n += count;
  return n;
}
int FakeServer::packages_received() const {
  std::lock_guard lock(mu_);
  return packages_;
}
int FakeServer::repeated_packages() const {
  std::lock_guard lock(mu_);
  return repeated_;
}
int FakeServer::heartbeats() const {
  std::lock_guard lock(mu_);
  return heartbeats_;
}
bool FakeServer::panic() const {
  std::lock_guard lock(mu_);
  return panic_;
}

void FakeServer::SendLocked(robotalk_msgs::reply_package_t p) {
  p.protocol_version = kProtocolVersion;
  p.server_id = server_id_;
  if (p.session_status == robotalk_msgs::reply_package_t::SESSION_OK) p.session_id = sessions_[p.client_id];
  p.server_send_us = ServerNowUs();
  p.num_replies = static_cast<std::int32_t>(p.replies.size());
  if (std::uniform_real_distribution<double>(0, 1)(rng_) < options_.reply_drop_probability) return;
  const std::string channel =
      "ROBOTALK/" + model_.name() + "/REPLY/" + Hex(static_cast<std::uint64_t>(p.client_id));
  Publish(transport_, channel, p);
  if (options_.duplicate_replies) Publish(transport_, channel, p);
}

void FakeServer::OnRequest(std::span<const std::uint8_t> bytes) {
  const std::int64_t receive_us = ServerNowUs();
  robotalk_msgs::package_t pkg;
  try {
    pkg = DecodePackage(bytes);
  } catch (const std::exception&) {
    return;
  }
  std::lock_guard lock(mu_);
  ++packages_;
  if (options_.mute) return;
  const auto& h = pkg.header;
  robotalk_msgs::reply_package_t out{};
  out.client_id = h.client_id;
  out.ack_sequence = h.sequence;
  out.server_receive_us = receive_us;
  if (auto session = sessions_.find(h.client_id);
      session == sessions_.end() || session->second != h.session_id) {
    out.session_status = robotalk_msgs::reply_package_t::SESSION_UNKNOWN;
    out.session_id = h.session_id;
    SendLocked(out);
    return;
  }

  const auto key = std::make_pair(h.client_id, h.sequence);
  if (auto it = seen_.find(key); it != seen_.end()) {
    // Rule 3: never execute again; re-send the ack and the finals we have.
    ++repeated_;
    for (std::int64_t id : it->second) {
      if (auto f = finals_.find(id); f != finals_.end()) out.replies.push_back(f->second);
    }
    SendLocked(out);
    return;
  }
  std::vector<std::int64_t>& ids = seen_[key];
  if (h.panic) panic_ = true;
  if (h.payload_size == 0 && !h.panic) ++heartbeats_;

  std::vector<robotalk_msgs::reply_t> now_replies;
  for (const auto& q : pkg.queries) {
    ids.push_back(q.id);
    robotalk_msgs::reply_t r;
    switch (q.type) {
      case robotalk_msgs::query_t::CONFIG: {
        const auto config = EncodeConfig(model_);
        transport_.Publish(ConfigChannel(model_.name()), config);
        r = MakeReply(q.id, 0, Hex(ConfigHash(model_)), receive_us);
        break;
      }
      case robotalk_msgs::query_t::JOINT_STATE:
        r = MakeReply(q.id, 0, "", receive_us,
                      std::vector<double>(3 * static_cast<size_t>(model_.num_dofs()), 0.0));
        break;
      default:
        r = MakeReply(q.id, 0, "", receive_us);
        break;
    }
    now_replies.push_back(r);
  }
  for (const auto& c : pkg.commands) {
    ids.push_back(c.id);
    ++executions_[c.id];
    if (h.panic) {
      now_replies.push_back(MakeReply(c.id, robotalk_msgs::reply_t::PANIC, "panic package", receive_us));
    } else if (c.type == robotalk_msgs::command_t::PANIC_RESET) {
      panic_ = false;
      now_replies.push_back(MakeReply(c.id, 0, "", receive_us));
    } else if (panic_) {
      now_replies.push_back(MakeReply(c.id, robotalk_msgs::reply_t::PANIC, "robot in panic", receive_us));
    } else if (c.start_time_us > receive_us) {
      delayed_.push_back(
          {c.start_time_us, h.client_id, MakeReply(c.id, 0, "cmd " + std::to_string(c.id), 0)});
    } else {
      now_replies.push_back(MakeReply(c.id, 0, "cmd " + std::to_string(c.id), receive_us));
    }
  }
  for (const auto& r : now_replies) finals_[r.id] = r;
  if (options_.reverse_batches && now_replies.size() > 1) {
    SendLocked(out);  // the ack alone
    for (auto it = now_replies.rbegin(); it != now_replies.rend(); ++it) {
      robotalk_msgs::reply_package_t one{};
      one.client_id = h.client_id;
      one.replies.push_back(*it);
      SendLocked(one);
    }
    return;
  }
  out.replies = std::move(now_replies);
  SendLocked(out);
}

void FakeServer::Worker() {
  while (!stop_) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    std::lock_guard lock(mu_);
    const std::int64_t now = ServerNowUs();
    for (auto it = delayed_.begin(); it != delayed_.end();) {
      if (it->due_us > now) {
        ++it;
        continue;
      }
      robotalk_msgs::reply_t r = it->reply;
      r.exec_time_us = now;
      r.lateness_us = now - it->due_us;
      finals_[r.id] = r;
      robotalk_msgs::reply_package_t p{};
      p.client_id = it->client_id;
      p.replies.push_back(r);
      it = delayed_.erase(it);
      if (options_.drop_first_delayed_reply && !dropped_first_delayed_) {
        dropped_first_delayed_ = true;  // lost: only a resend after the start recovers it
        continue;
      }
      if (!options_.mute) SendLocked(p);
    }
  }
}

}  // namespace robotalk::testing

// RobotClient::Impl: what the server multicasts to every reader -- the
// configuration (CONFIG) and the state stream (STATE). In keyed mode each
// must carry the trusted server key's signature for the live session's
// server instance (docs/security.md, "Which server?"); anything else is
// dropped and counted (issue 19: forged STATE was printed by a keyed
// `robotalk watch`, forged CONFIG grew its memory without bound).
#include "client_impl.h"

#include "robotalk/broadcast_signature.h"
#include "robotalk/config_message.h"
#include "robotalk/request.h"

namespace robotalk {

std::optional<std::span<const std::uint8_t>> RobotClient::Impl::Authentic(
    const std::string& channel, std::span<const std::uint8_t> bytes) {
  std::optional<PublicKey> key;
  std::optional<Nonce> instance;
  {
    std::lock_guard lock(mu_);
    if (!identity_) return WithoutSignature(bytes);  // open mode trusts the LAN
    if (trust_ && trust_->trusted()) key = trust_->trusted();
    if (session_keys_) instance = session_keys_->instance_nonce;
  }
  // Before the first session nothing is trusted yet: nothing is accepted.
  // The signature check (~60 µs) runs outside the lock.
  if (key && instance && VerifyBroadcast(channel, bytes, *key, &*instance) == BroadcastVerdict::kAuthentic) {
    return WithoutSignature(bytes);
  }
  std::lock_guard lock(mu_);
  ++stats_.broadcasts_refused;
  return std::nullopt;
}

void RobotClient::Impl::OnConfig(std::span<const std::uint8_t> signed_bytes) {
  try {
    std::string channel;
    {
      std::lock_guard lock(mu_);
      channel = ConfigChannel(robot_);
    }
    const auto bytes = Authentic(channel, signed_bytes);
    if (!bytes) return;
    try {
      const auto hash = DecodeConfigHash(*bytes);
      {
        std::lock_guard lock(mu_);
        if (configs_.Has(hash)) return;  // cached: skip decoding the blocks
      }
      auto model = std::make_shared<const RobotModel>(DecodeConfig(*bytes));
      {
        std::lock_guard lock(mu_);
        if (resync_hash_ == hash) {
          model_ = model;  // the new server instance's description
          resync_hash_.reset();
          configs_.Want(hash);  // kept: it is in use
        }
        configs_.Add(hash, std::move(model), bytes->size());
      }
      cv_.notify_all();
    } catch (const Error& e) {
      std::lock_guard lock(mu_);
      ++stats_.malformed_packages;
      last_config_error_ = e.what();
    }
  } catch (...) {
    std::lock_guard lock(mu_);
    daemon_error_ = std::current_exception();
  }
}

// On the ReadDaemon: a bad sample is counted, a callback's exception stored.
void RobotClient::Impl::OnState(std::span<const std::uint8_t> signed_bytes) {
  std::function<void(const StateSample&)> callback;
  int dofs = -1;
  std::string channel;
  {
    std::lock_guard lock(mu_);
    callback = on_state_;
    if (model_) dofs = model_->num_dofs();
    channel = StateChannel(robot_);
  }
  if (!callback) return;
  const auto bytes = Authentic(channel, signed_bytes);
  if (!bytes) return;
  StateSample state;
  try {
    state = DecodeStateSample(*bytes, dofs);
  } catch (const ProtocolError&) {
    std::lock_guard lock(mu_);
    ++stats_.malformed_packages;
    return;
  }
  {
    std::lock_guard lock(mu_);
    if (session_keys_) {
      // Keyed: an authentic sample older than the newest one of its instance
      // is a replay (a recording played back inside the session).
      const std::int64_t at = ToWireMicros(state.server_time);
      if (last_state_instance_ != session_keys_->instance_nonce) {
        last_state_instance_ = session_keys_->instance_nonce;
        last_state_us_.reset();
      }
      if (last_state_us_ && at <= *last_state_us_) {
        ++stats_.broadcasts_refused;
        return;
      }
      last_state_us_ = at;
    }
  }
  try {
    callback(state);
  } catch (...) {
    std::lock_guard lock(mu_);
    if (!daemon_error_) daemon_error_ = std::current_exception();
  }
}

}  // namespace robotalk

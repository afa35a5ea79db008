// Which server key a keyed client accepts (docs/security.md, "Which server?").
//
// Decision: an explicit key (ClientOptions::server_key_file, CLI --server-key)
// when given, and nothing else; otherwise trust on first use, pinned per
// robot and network in the known-servers file (known_servers.h), like SSH's
// known_hosts: the first server that answers with a valid signature is
// pinned (and the client says so), a later server with another key is
// refused with both fingerprints and the fix. Once trusted, a client keeps
// the key for its lifetime: a restarted server must answer with the same key.
//
// Thread safety: none; RobotClient::Impl uses it under its mutex, and calls
// WritePin() (file I/O) outside it.
#pragma once

#include "robotalk/keys.h"
#include "robotalk/robot_client.h"

#include <filesystem>
#include <optional>
#include <string>

namespace robotalk::client {

class ServerTrust {
 public:
  /// `explicit_key`: the key to demand (the pin file is then neither read
  /// nor written); `explicit_file` names it in messages. `pin_file`: the
  /// known-servers file; empty when there is none to use.
  ServerTrust(std::optional<PublicKey> explicit_key, std::string explicit_file,
              std::filesystem::path pin_file);

  /// Reads the pin of `robot` on `network` (at Connect).
  /// @throw KeyError: no pin file can be named, or it is unusable (the message names it).
  void Load(const std::string& robot, const std::string& network);

  /// "" when `offered` (the key that signed a hello answer) may be trusted;
  /// otherwise why not, naming both fingerprints and how to fix it.
  std::string Check(const PublicKey& offered) const;
  /// True when Check() passed for a key nobody pinned yet: WritePin() and
  /// Trust() must record it.
  bool first_use() const { return !trusted_; }
  /// First use: appends `key` to the pin file. Reads only what Load() set,
  /// so it may run outside the caller's lock.
  /// @throw KeyError when the pin cannot be written.
  void WritePin(const PublicKey& key) const;
  /// Trusts `key` from now on (after Check, and WritePin on first use).
  void Trust(const PublicKey& key);

  const std::optional<PublicKey>& trusted() const { return trusted_; }
  TrustedServer Describe() const;

 private:
  std::string explicit_file_;
  std::filesystem::path pin_file_;
  std::string robot_, network_;
  std::optional<PublicKey> trusted_;
  TrustedServer::Source source_ = TrustedServer::Source::kNone;
  int pin_line_ = 0;
};

}  // namespace robotalk::client

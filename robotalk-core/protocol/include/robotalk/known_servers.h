// Which server key a keyed client trusts for a robot: trust on first use,
// pinned in a file like SSH's known_hosts (docs/security.md, "Which server?").
//
// File (default ~/.robotalk/known_servers; $ROBOTALK_KNOWN_SERVERS or
// ClientOptions::known_servers_file overrides), one pin per line, '#' comments:
//
//   <robot> <network> ed25519:<64 hex digits>
//   pioneer udpm://239.255.76.67:7667
//   ed25519:411d026d5dd53d20c89153788ab1d4a4ce5944f907fc0a286b2c43bdb6e0b88b
//
// <network> is the LCM URL without its options (PinNetwork): the same robot
// name on another bus is another robot. The whole key is kept (not only its
// fingerprint, which is 64 bits). Whoever can write this file decides which
// server the client obeys, so it must be a regular file (not a symlink)
// owned by the user, that group and others cannot write.
//
// Thread safety: a KnownServers is a plain value; the functions may be
// called from any thread (two processes appending at once each write one
// whole line with O_APPEND).
#pragma once

#include "robotalk/keys.h"

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk {

struct ServerPin {
  std::string robot;
  std::string network;
  PublicKey key;
  int line = 0;  ///< where it is in the file (1-based); 0 = not from a file
};

class KnownServers {
 public:
  /// Reads `file`; a file that does not exist is an empty list.
  /// @throw KeyError naming FILE:LINE and what is wrong: a malformed line or
  ///   key, a robot pinned twice on one network with different keys, a
  ///   symlink, a file of another user or one that group or others may write.
  static KnownServers Read(const std::filesystem::path& file);

  /// The pin of `robot` on `network`, or nullptr.
  const ServerPin* Find(std::string_view robot, std::string_view network) const;
  const std::filesystem::path& file() const { return file_; }
  const std::vector<ServerPin>& pins() const { return pins_; }

  /// Adds a line for `pin` to `file`, creating the file (mode 0600) and its
  /// directory (mode 0700) when missing.
  /// @throw KeyError naming the file (cannot create or write, wrong owner or mode).
  static void Append(const std::filesystem::path& file, const ServerPin& pin);

 private:
  std::filesystem::path file_;
  std::vector<ServerPin> pins_;
};

/// The network part of an LCM URL as pins name it: the URL without its
/// options ("udpm://239.255.76.67:7667?ttl=0&traffic=split" ->
/// "udpm://239.255.76.67:7667").
std::string PinNetwork(std::string_view lcm_url);

/// $ROBOTALK_KNOWN_SERVERS, else $HOME/.robotalk/known_servers; empty when
/// neither variable is set.
std::filesystem::path DefaultKnownServersFile();

}  // namespace robotalk

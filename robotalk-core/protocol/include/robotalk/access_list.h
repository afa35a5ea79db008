// The server's access list (`--clients FILE`): which public keys may talk to
// it, under which name, and with which rights per robot. docs/security.md.
//
// Format: UTF-8 text, one client per line; blank lines and lines starting
// with '#' are ignored; fields are separated by spaces or tabs:
//
//   <public key> <name> <robot>=<rights> [<robot>=<rights> ...]
//
//   ed25519:3b6a27bc...(64 hex)  alice   pioneer=command,query,panic  *=query
//   ed25519:9f0c11d2...(64 hex)  monitor *=query
//
// - <public key> <name> is exactly a robotalk-keygen .pub line; names are
//   1-64 of [A-Za-z0-9_.@-], unique in the file (logs name clients by it).
// - <robot> is a robot name ([A-Za-z0-9_-]) or '*' for every robot; a named
//   robot's entry replaces the '*' entry for that robot (so '*=all
//   arm=query' gives everything except commanding 'arm').
// - <rights> is a comma list of: command (motion commands, STOP,
//   PANIC_RESET), query (queries, incl. CONFIG and the STATE stream, i.e.
//   `watch`), panic (raise a panic); 'all' = all three; 'none' = nothing.
// - A key may appear once. Every error names FILE:LINE and the bad token.
//
// Thread safety: an AccessList is immutable after Parse; const members may be
// called from any thread.
#pragma once

#include "robotalk/error.h"
#include "robotalk/keys.h"

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace robotalk {

struct Request;  // robotalk/request.h

/// The access list is malformed or its file unreadable / too open.
/// The message starts with "FILE:LINE: " when a line is at fault.
class AccessListError : public Error {
 public:
  using Error::Error;
};

/// What a key may do on one robot.
struct Rights {
  bool command = false;  ///< motion commands, STOP, PANIC_RESET
  bool query = false;    ///< queries, CONFIG, STATE stream (watch)
  bool panic = false;    ///< raise a panic

  static Rights All() { return {true, true, true}; }
  bool any() const { return command || query || panic; }
  /// "command,query,panic", a subset, or "none".
  std::string ToString() const;
  friend bool operator==(const Rights&, const Rights&) = default;
};

/// One line of the list.
struct AccessEntry {
  PublicKey key;
  std::string name;
  std::map<std::string, Rights, std::less<>> robots;  ///< robot name or "*"
  int line = 0;                                       ///< where it was defined (1-based)
};

class AccessList {
 public:
  /// Parses `text`; `source` names it in errors (a file name).
  /// @throw AccessListError "SOURCE:LINE: ..." naming the bad token.
  static AccessList Parse(std::string_view text, std::string_view source);
  /// Reads and parses `file`. Refuses a file that group or others may write
  /// (they could grant themselves rights), naming the file and its mode.
  /// @throw AccessListError
  static AccessList ReadFile(const std::filesystem::path& file);

  /// The entry of `key`, or nullptr for a key not in the list.
  const AccessEntry* Find(const PublicKey& key) const;
  /// The rights of `key` on `robot`: its robot entry, else its '*' entry,
  /// else none. An unknown key has no rights.
  Rights RightsFor(const PublicKey& key, std::string_view robot) const;

  const std::vector<AccessEntry>& entries() const { return entries_; }
  std::size_t size() const { return entries_.size(); }

 private:
  std::vector<AccessEntry> entries_;
  struct KeyLess {
    bool operator()(const PublicKey& a, const PublicKey& b) const { return a.bytes < b.bytes; }
  };
  std::map<PublicKey, std::size_t, KeyLess> by_key_;  // index into entries_
};

/// The rights a package needs: panic for the panic flag, command for any
/// command (PANIC_RESET and STOP included), query for any query. A heartbeat
/// (no items, no panic) needs none: it only keeps an authenticated session alive.
Rights RequiredRights(const Request& request);

/// Empty when `entry` may send `request` to `robot`; otherwise the refusal,
/// naming the client, the robot and the missing rights ("client 'monitor'
/// may not command robot 'pioneer' (its rights there: query)").
std::string CheckRights(const AccessList& list, const AccessEntry& entry, std::string_view robot,
                        const Request& request);

}  // namespace robotalk

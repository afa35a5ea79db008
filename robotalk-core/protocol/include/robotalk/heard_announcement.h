// One ROBOTALK/ANNOUNCE datagram as every reader that lists robots takes it
// (ListRobots, `robotalk watch`, robotalk-web): checked, decoded, and with a
// trusted server key, only what that key signed.
//
// Thread safety: a pure function. Errors: none thrown; a datagram not taken
// is nullopt (anyone on the LAN can send one: dropping is the answer).
#pragma once

#include "robotalk/keys.h"
#include "robotalk/request.h"

#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace robotalk {

struct HeardAnnouncement {
  Announcement announcement;
  std::string server_key;  ///< the key that signed it ("ed25519:<64 hex>"), "" unsigned
};

/// nullopt when `bytes` do not decode (the checked decoder: hostile counts
/// never reach an allocation), when their signature suffix does not verify,
/// or, with `only` given, when `only` did not sign them. With `only`, the key
/// is compared before the signature is verified, so others' announcements
/// cost no verification.
std::optional<HeardAnnouncement> HearAnnouncement(std::span<const std::uint8_t> bytes,
                                                  const PublicKey* only = nullptr);

}  // namespace robotalk

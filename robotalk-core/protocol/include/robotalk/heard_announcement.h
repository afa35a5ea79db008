// One ROBOTALK/ANNOUNCE datagram as every reader that lists robots takes it
// (ListRobots, `robotalk watch`, robotalk-web): checked, decoded, and with a
// trusted server key, only what that key signed.
//
// Thread safety: a pure function. Errors: none thrown; a datagram not taken
// is nullopt (anyone on the LAN can send one: dropping is the answer).
#pragma once

#include "robotalk/clock.h"
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

/// The one freshness rule for a signed announcement (`robotalk watch`; a
/// keyed client's panic, RobotClient): it proves its server was alive at its
/// signed server time, not when it arrives (a captured one can be replayed
/// later). `announced` is that time on the reader's clock (a synchronised
/// client's ClientTime). Returns when it shows the server alive, never later
/// than `now`; nullopt when that is more than kAnnounceHeardWithin (one
/// announce period and slack for the network and the clock sync) before
/// `now`: replayed or delayed, it does not show the server is there. Also
/// nullopt when `announced` is more than kAnnounceHeardWithin after `now`:
/// signed by an instance whose clock ran ahead of the one the reader is
/// synchronised with (its host's before a reboot), never by that server;
/// replayed, it would show a server alive for as long as its stamp is ahead.
std::optional<TimePoint> FreshAnnouncementTime(TimePoint now, TimePoint announced);

}  // namespace robotalk

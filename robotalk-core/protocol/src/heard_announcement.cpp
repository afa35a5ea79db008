#include "robotalk/heard_announcement.h"

#include "robotalk/broadcast_signature.h"
#include "robotalk/channels.h"
#include "robotalk/error.h"

#include <algorithm>

namespace robotalk {

std::optional<HeardAnnouncement> HearAnnouncement(std::span<const std::uint8_t> bytes,
                                                  const PublicKey* only) {
  HeardAnnouncement heard;
  if (only) {
    if (VerifyBroadcast(kAnnounceChannel, bytes, *only, nullptr) != BroadcastVerdict::kAuthentic)
      return std::nullopt;
    heard.server_key = only->ToString();
  } else if (SignatureSuffix(bytes)) {
    const std::optional<SignedBy> by = VerifySelfSigned(kAnnounceChannel, bytes);
    if (!by) return std::nullopt;  // a suffix that does not verify: forged
    heard.server_key = by->server_key.ToString();
  }
  try {
    heard.announcement = DecodeAnnouncement(bytes);
  } catch (const ProtocolError&) {
    return std::nullopt;
  }
  return heard;
}

std::optional<TimePoint> FreshAnnouncementTime(TimePoint now, TimePoint announced) {
  if (announced - now > kAnnounceHeardWithin) return std::nullopt;  // of a clock ahead of the reader's
  const TimePoint at = std::min(now, announced);
  if (now - at > kAnnounceHeardWithin) return std::nullopt;
  return at;
}

}  // namespace robotalk

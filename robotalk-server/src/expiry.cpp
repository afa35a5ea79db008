#include "expiry.h"

#include <cstdio>

namespace robotalk {

namespace {
constexpr const char* kPrefix = "expired: ";

std::string Secs(Duration d) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g s", ToSeconds(d));
  return buf;
}
}  // namespace

Duration EffectiveMaxLate(CommandType type, bool has_start_time, Duration requested, Duration robot_default) {
  const CommandTraits& traits = Traits(type);
  // A STOP always runs; a command due "now" cannot be late.
  if (!has_start_time || traits.kind == CommandKind::kStop || traits.kind == CommandKind::kSession) {
    return kNeverExpires;
  }
  if (requested > Duration::zero()) return requested;  // the client's limit, or never (max)
  return traits.kind == CommandKind::kServo ? robot_default : kNeverExpires;
}

std::optional<std::string> ExpiryRefusal(Duration lateness, Duration max_late,
                                         std::optional<Duration> arrival_lateness) {
  if (max_late == kNeverExpires || lateness <= max_late) return std::nullopt;
  const Duration arrived = arrival_lateness.value_or(lateness);
  if (arrived > max_late || !arrival_lateness) {
    return kPrefix + std::string("arrived ") + Secs(arrived) + " after its start, limit " + Secs(max_late);
  }
  return kPrefix + std::string("began ") + Secs(lateness) + " after its start (it arrived " +
         (arrived > Duration::zero() ? Secs(arrived) + " after it" : std::string("in time")) + "), limit " +
         Secs(max_late);
}

bool IsExpiryReply(const Reply& reply) {
  return reply.signal == Signal::kInterrupted && reply.message.starts_with(kPrefix);
}

ExpiryHold HoldAfterExpiry(CommandType type, int target) {
  const CommandTraits& traits = Traits(type);
  if (traits.kind != CommandKind::kServo || !traits.keeps_moving) return {};
  if (traits.target == CommandTarget::kJoint) return {.joint = target};
  if (traits.target == CommandTarget::kBase) return {.base = true};
  return {};
}

}  // namespace robotalk

#include "fuzz_targets.h"

#include "robotalk/config_codec.h"
#include "robotalk/error.h"
#include "robotalk/protocol_codec.h"
#include "robotalk/urdf_import.h"
#include "robotalk_msgs/announce_t.hpp"

#include <climits>
#include <string>

namespace robotalk::fuzz {

void Package(Bytes bytes) {
  try {
    const robotalk_msgs::package_t p = DecodePackage(bytes);
    if (!CheckPackageHeader(p).empty()) return;  // refused with ERROR on the wire
    for (const auto& q : p.queries) {
      try {
        (void)FromWire(q);
      } catch (const ProtocolError&) {
      }
    }
    for (const auto& c : p.commands) {
      try {
        (void)FromWire(c);
      } catch (const ProtocolError&) {
      }
    }
  } catch (const Error&) {
  }
}

void ReplyPackage(Bytes bytes) {
  try {
    const robotalk_msgs::reply_package_t p = DecodeReplyPackage(bytes);
    for (const auto& r : p.replies) {
      try {
        (void)FromWire(r);
      } catch (const ProtocolError&) {
      }
    }
  } catch (const Error&) {
  }
}

void RobotState(Bytes bytes) {
  try {
    (void)DecodeRobotState(bytes);
  } catch (const Error&) {
  }
}

void Config(Bytes bytes) {
  try {
    (void)DecodeConfigHeader(bytes);
    (void)DecodeConfig(bytes);
  } catch (const Error&) {
  }
}

void Announce(Bytes bytes) {
  // lcm-cpp's trampoline: decode, drop the message when the status is < 0.
  if (bytes.size() > static_cast<std::size_t>(INT_MAX)) return;
  robotalk_msgs::announce_t msg;
  (void)msg.decode(bytes.data(), 0, static_cast<int>(bytes.size()));
}

void Urdf(Bytes bytes) {
  try {
    (void)ParseUrdf(std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()), {}, "fuzz.urdf");
  } catch (const Error&) {
  }
}

std::span<const Target> Targets() {
  static const Target targets[] = {
      {"package", &Package}, {"reply_package", &ReplyPackage}, {"robot_state", &RobotState},
      {"config", &Config},   {"announce", &Announce},          {"urdf", &Urdf},
  };
  return targets;
}

}  // namespace robotalk::fuzz

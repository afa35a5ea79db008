// The bridge's guard in front of LCM's announce decoder: a hostile robot count
// must not reach the decoder, which would allocate the array from it.
#include "robot_tracker.h"
#include "robotalk_msgs/announce_t.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace robotalk::web {
namespace {

std::vector<std::uint8_t> Encode(int robots, const std::string& url = "udpm://x") {
  robotalk_msgs::announce_t a{};
  a.protocol_version = 1;
  a.server_id = 42;
  a.url_hint = url;
  for (int i = 0; i < robots; ++i) {
    robotalk_msgs::robot_info_t r{};
    r.name = "robot" + std::to_string(i);
    r.driver = "ode";
    a.robots.push_back(r);
  }
  a.num_robots = robots;
  std::vector<std::uint8_t> bytes(static_cast<size_t>(a.getEncodedSize()));
  a.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

// Offset of num_robots: fingerprint, version, server id, time, uptime, url (length + text + NUL).
size_t CountOffset(const std::string& url) { return 8 + 2 + 8 + 8 + 8 + 4 + url.size() + 1; }

TEST(AnnounceCountPlausible, AcceptsRealAnnounces) {
  for (int n : {0, 1, 3}) EXPECT_TRUE(AnnounceCountPlausible(Encode(n))) << n;
}

TEST(AnnounceCountPlausible, RefusesACountTheDatagramCannotHold) {
  auto bytes = Encode(1);
  const size_t at = CountOffset("udpm://x");
  bytes[at] = 0x10;  // 268 million robots in a datagram of ~70 bytes
  EXPECT_FALSE(AnnounceCountPlausible(bytes));
  bytes[at] = 0xff;  // negative
  EXPECT_FALSE(AnnounceCountPlausible(bytes));
}

TEST(AnnounceCountPlausible, RefusesTruncatedBytesAndAnOverlongUrl) {
  const auto bytes = Encode(2);
  for (size_t n : {size_t{0}, size_t{10}, size_t{37}, CountOffset("udpm://x") + 2})
    EXPECT_FALSE(AnnounceCountPlausible(std::span(bytes.data(), n))) << n;
  auto long_url = Encode(1);
  long_url[34] = 0x7f;  // url length far beyond the datagram
  EXPECT_FALSE(AnnounceCountPlausible(long_url));
}

}  // namespace
}  // namespace robotalk::web

// The panic latch file (panic_latch.h): scoped per network, shared safely
// between servers, and refused loudly where it cannot be written (issue 19).
#include "panic_latch.h"

#include "robotalk/error.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdlib>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

namespace robotalk {
namespace {

using ::testing::HasSubstr;

std::string FreshDir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "/panic_latch_test_" + name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(PanicLatch, KeepsOneFilePerNetworkSoServersOnOtherPortsDoNotLatchEachOther) {
  EXPECT_EQ(PanicLatch::LatchFileFor("/s", "udpm://239.255.76.67:7667?ttl=0"),
            "/s/panic-latch.udpm-239.255.76.67-7667");
  // Options do not change the network; the port and group do.
  EXPECT_EQ(PanicLatch::LatchFileFor("/s", "udpm://239.255.76.67:7667?ttl=1&traffic=single"),
            "/s/panic-latch.udpm-239.255.76.67-7667");
  EXPECT_NE(PanicLatch::LatchFileFor("/s", "udpm://239.255.76.67:7668?ttl=0"),
            PanicLatch::LatchFileFor("/s", "udpm://239.255.76.67:7667?ttl=0"));
  EXPECT_NE(PanicLatch::LatchFileFor("/s", "udpm://239.255.76.68:7667"),
            PanicLatch::LatchFileFor("/s", "udpm://239.255.76.67:7667"));
  EXPECT_EQ(PanicLatch::LatchFileFor("/s", "memory://"), "/s/panic-latch.memory");
  // Nothing in a URL leaves the directory.
  EXPECT_EQ(PanicLatch::LatchFileFor("/s", "file:///../../etc/x"), "/s/panic-latch.file--..-..-etc-x");
}

TEST(PanicLatch, TwoServersSharingOneFileKeepEachOthersRobots) {
  const std::string file = FreshDir("shared") + "/latch";
  PanicLatch a(file), b(file);
  a.Load();
  b.Load();
  a.Set("pioneer", "PANIC from a client");
  b.Set("arm", "driver fault");
  a.Clear("nothing-here");
  PanicLatch restarted(file);
  const auto latched = restarted.Load();
  EXPECT_EQ(latched.size(), 2u);
  EXPECT_EQ(latched.at("pioneer"), "PANIC from a client");
  EXPECT_EQ(latched.at("arm"), "driver fault");
  b.Clear("arm");
  EXPECT_EQ(PanicLatch(file).Load().count("arm"), 0u);
  EXPECT_EQ(PanicLatch(file).Load().count("pioneer"), 1u);
}

TEST(PanicLatch, TheDefaultStateDirectoryFollowsTheEnvironment) {
  ::setenv("ROBOTALK_STATE_DIR", "/tmp/rt-state", 1);
  EXPECT_EQ(PanicLatch::DefaultStateDir(), "/tmp/rt-state");
  ::unsetenv("ROBOTALK_STATE_DIR");
  if (::geteuid() == 0) {
    EXPECT_EQ(PanicLatch::DefaultStateDir(), "/var/lib/robotalk");
  } else {
    ::setenv("XDG_STATE_HOME", "/tmp/xdg", 1);
    EXPECT_EQ(PanicLatch::DefaultStateDir(), "/tmp/xdg/robotalk");
    ::unsetenv("XDG_STATE_HOME");
    ::setenv("HOME", "/home/someone", 1);
    EXPECT_EQ(PanicLatch::DefaultStateDir(), "/home/someone/.local/state/robotalk");
  }
}

TEST(PanicLatch, AStateDirectoryOrFileThatCannotBeMadeIsAnErrorNamingIt) {
  const std::string dir = FreshDir("unusable");
  std::ofstream(dir + "/plain_file") << "x";
  EXPECT_THAT(ErrorOf([&] { PanicLatch::MakeStateDir(dir + "/plain_file/state"); }),
              HasSubstr("state directory '" + dir + "/plain_file/state': cannot create"));
  EXPECT_THAT(ErrorOf([&] { PanicLatch latch(dir + "/missing/latch"); }),
              HasSubstr("panic latch '" + dir + "/missing/latch': cannot create"));
  PanicLatch::MakeStateDir(dir + "/a/b/c");
  EXPECT_TRUE(std::filesystem::is_directory(dir + "/a/b/c"));
  EXPECT_EQ(std::filesystem::status(dir + "/a/b/c").permissions() & std::filesystem::perms::all,
            std::filesystem::perms::owner_all);
}

}  // namespace
}  // namespace robotalk

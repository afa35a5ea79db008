// The known-servers pin file (robotalk/known_servers.h).
#include "robotalk/known_servers.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>
#include "support/test_keys.h"

#include <filesystem>
#include <fstream>
#include <random>

namespace robotalk {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

PublicKey Key(std::uint8_t seed) { return testing::TestKey(seed).public_key; }

class KnownServersTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("robotalk_known_servers_test_" + std::to_string(::getpid()) + "_" +
                                        std::to_string(std::mt19937_64(std::random_device{}())()));
    fs::create_directories(dir_);
    file_ = dir_ / "sub" / "known_servers";
  }
  void TearDown() override { fs::remove_all(dir_); }
  void Write(const std::string& text, mode_t mode = 0600) {
    fs::create_directories(file_.parent_path());
    std::ofstream(file_) << text;
    ::chmod(file_.c_str(), mode);
  }
  std::string ReadError() {
    try {
      KnownServers::Read(file_);
    } catch (const KeyError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_, file_;
};

TEST_F(KnownServersTest, AMissingFileIsEmptyAndAnAppendedPinIsFoundAgainPrivately) {
  EXPECT_TRUE(KnownServers::Read(file_).pins().empty());
  KnownServers::Append(file_, {"pioneer", "udpm://239.255.76.67:7667", Key(1)});
  KnownServers::Append(file_, {"arm", "udpm://239.255.76.67:7667", Key(2)});
  const KnownServers pins = KnownServers::Read(file_);
  ASSERT_NE(pins.Find("pioneer", "udpm://239.255.76.67:7667"), nullptr);
  EXPECT_EQ(pins.Find("pioneer", "udpm://239.255.76.67:7667")->key, Key(1));
  EXPECT_EQ(pins.Find("arm", "udpm://239.255.76.67:7667")->line, 2);
  EXPECT_EQ(pins.Find("pioneer", "udpm://239.255.76.67:7000"), nullptr) << "another bus, another robot";
  struct stat st {};
  ASSERT_EQ(::stat(file_.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  ASSERT_EQ(::stat(file_.parent_path().c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0700u);
}

TEST_F(KnownServersTest, AMalformedLineIsAnErrorNamingFileAndLine) {
  Write("# pins\npioneer udpm://g:1\n");
  EXPECT_THAT(ReadError(), HasSubstr(file_.string() + ":2: expected '<robot> <network> ed25519:<64 hex>'"));
  Write("pioneer udpm://g:1 ed25519:1234\n");
  EXPECT_THAT(ReadError(), HasSubstr(":1: "));
}

TEST_F(KnownServersTest, TwoDifferentKeysForOneRobotAreAnErrorNamingBothLines) {
  Write("pioneer net " + Key(1).ToString() + "\npioneer net " + Key(1).ToString() + "\npioneer net " +
        Key(2).ToString() + "\n");
  EXPECT_THAT(ReadError(), HasSubstr(":3: robot 'pioneer' on net is pinned to " + Key(2).Fingerprint() +
                                     " here and to " + Key(1).Fingerprint() + " on line 1"));
}

TEST_F(KnownServersTest, AFileOthersMayWriteOrASymlinkIsRefused) {
  Write("pioneer net " + Key(1).ToString() + "\n", 0620);
  EXPECT_THAT(ReadError(), HasSubstr("mode 0620 lets group or others write it"));
  EXPECT_THROW(KnownServers::Append(file_, {"arm", "net", Key(2)}), KeyError);
  ::chmod(file_.c_str(), 0600);
  const fs::path link = dir_ / "link";
  fs::create_symlink(file_, link);
  file_ = link;
  EXPECT_THAT(ReadError(), HasSubstr("is a symlink"));
}

// Whoever may replace the file chooses the server too: its directories are
// checked like the key files' (file_trust.h).
TEST_F(KnownServersTest, AFileInAWorldWritableDirectoryIsRefusedUnlessTheDirectoryIsSticky) {
  Write("pioneer net " + Key(1).ToString() + "\n");
  ::chmod(file_.parent_path().c_str(), 0777);
  EXPECT_THAT(ReadError(), HasSubstr("world-writable without the sticky bit"));
  ::chmod(file_.parent_path().c_str(), 01777);
  EXPECT_EQ(ReadError(), "");
}

TEST(PinNetwork, IsTheUrlWithoutItsOptions) {
  EXPECT_EQ(PinNetwork("udpm://239.255.76.67:7667?ttl=0&traffic=split"), "udpm://239.255.76.67:7667");
  EXPECT_EQ(PinNetwork("memory://"), "memory://");
}

}  // namespace
}  // namespace robotalk

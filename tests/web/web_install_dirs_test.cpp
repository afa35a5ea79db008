// Tests of where robotalk-web looks for its page when no option names it: the
// installation beside its binary (wherever that was moved), else the sources.
#include "web_install_dirs.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace robotalk::web {
namespace {

namespace fs = std::filesystem;

class DefaultWebDirsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("robotalk_web_dirs_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_ / "moved/bin");
  }
  void TearDown() override { fs::remove_all(root_); }
  void InstallPage() {
    fs::create_directories(root_ / "moved/share/robotalk/web/www");
    std::ofstream(root_ / "moved/share/robotalk/web/www/index.html") << "<html></html>\n";
  }
  fs::path root_;
};

TEST_F(DefaultWebDirsTest, FindsTheInstalledPageRelativeToTheBinary) {
  InstallPage();
  const WebDirs d = DefaultWebDirs(root_ / "moved/bin", "../share/robotalk/web", "/src/tools/web");
  EXPECT_EQ(d.www, (root_ / "moved/share/robotalk/web/www").string());
  EXPECT_EQ(d.node_modules, (root_ / "moved/share/robotalk/web/node_modules").string());
}

TEST_F(DefaultWebDirsTest, FallsBackToTheSourcesWithoutAnInstalledPage) {
  const WebDirs d = DefaultWebDirs(root_ / "moved/bin", "../share/robotalk/web", "/src/tools/web");
  EXPECT_EQ(d.www, "/src/tools/web/www");
  EXPECT_EQ(d.node_modules, "/src/tools/web/node_modules");
}

TEST_F(DefaultWebDirsTest, FallsBackToTheSourcesWhenTheBinarysFolderIsUnknown) {
  InstallPage();
  EXPECT_EQ(DefaultWebDirs("", "../share/robotalk/web", "/src/tools/web").www, "/src/tools/web/www");
}

TEST(RunningBinaryDir, IsTheFolderOfThisTest) {
  const fs::path dir = RunningBinaryDir();
  ASSERT_FALSE(dir.empty());
  EXPECT_TRUE(fs::is_directory(dir));
  EXPECT_TRUE(dir.is_absolute());
}

}  // namespace
}  // namespace robotalk::web

// The --clients access list (robotalk/access_list.h).
#include "robotalk/access_list.h"

#include "robotalk/request.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace robotalk {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

PublicKey Key(std::uint8_t v) {
  std::array<std::uint8_t, 32> seed{};
  seed.fill(v);
  return KeyPair::FromSeed(seed).public_key;
}

std::string Line(std::uint8_t v, const std::string& rest) { return Key(v).ToString() + " " + rest + "\n"; }

// The message of the AccessListError `text` raises ("" when none).
std::string ErrorOf(const std::string& text) {
  try {
    AccessList::Parse(text, "clients.txt");
  } catch (const AccessListError& e) {
    return e.what();
  }
  return "";
}

TEST(AccessList, ParsesKeysNamesAndRightsSkippingCommentsAndBlankLines) {
  const AccessList list = AccessList::Parse("# operators\n\n" + Line(1, "alice pioneer=command,query,panic") +
                                                "   # indented comment\n" + Line(2, "monitor\t*=query"),
                                            "clients.txt");
  ASSERT_EQ(list.size(), 2U);
  const AccessEntry* alice = list.Find(Key(1));
  ASSERT_NE(alice, nullptr);
  EXPECT_EQ(alice->name, "alice");
  EXPECT_EQ(alice->line, 3);
  EXPECT_EQ(list.RightsFor(Key(1), "pioneer"), Rights::All());
  EXPECT_EQ(list.RightsFor(Key(2), "pioneer"), (Rights{false, true, false}));
}

TEST(AccessList, StarCoversEveryRobotAndANamedRobotReplacesIt) {
  const AccessList list = AccessList::Parse(Line(1, "alice *=all arm=query"), "c");
  EXPECT_EQ(list.RightsFor(Key(1), "pioneer"), Rights::All());
  EXPECT_EQ(list.RightsFor(Key(1), "arm"), (Rights{false, true, false}));
  const AccessList only = AccessList::Parse(Line(1, "alice arm=command"), "c");
  EXPECT_FALSE(only.RightsFor(Key(1), "pioneer").any());
  const AccessList none = AccessList::Parse(Line(1, "alice *=all arm=none"), "c");
  EXPECT_FALSE(none.RightsFor(Key(1), "arm").any());
}

TEST(AccessList, AKeyNotInTheListHasNoRights) {
  const AccessList list = AccessList::Parse(Line(1, "alice *=all"), "c");
  EXPECT_EQ(list.Find(Key(9)), nullptr);
  EXPECT_FALSE(list.RightsFor(Key(9), "pioneer").any());
}

TEST(AccessList, MalformedLinesAreErrorsNamingFileLineAndToken) {
  const std::string ok = Line(1, "alice *=all");
  struct Case {
    std::string text;
    std::string line;
    std::string fragment;
  };
  const std::vector<Case> cases{
      {ok + "ed25519:abcd bob *=all\n", "clients.txt:2: ", "ed25519:abcd"},
      {ok + Line(2, "bob"), "clients.txt:2: ", "got 2 field(s)"},
      {"\n" + Line(2, "bob pioneer=move"), "clients.txt:2: ", "unknown right 'move'"},
      {Line(2, "bob pioneer="), "clients.txt:1: ", "no rights"},
      {Line(2, "bob pioneer"), "clients.txt:1: ", "expected <robot>=<rights>"},
      {Line(2, "bob pio/neer=query"), "clients.txt:1: ", "robot 'pio/neer'"},
      {Line(2, "b$b *=query"), "clients.txt:1: ", "name 'b$b'"},
      {Line(2, "bob arm=query arm=command"), "clients.txt:1: ", "robot 'arm' given twice"},
      {ok + "#\n" + Line(1, "alice2 *=query"), "clients.txt:3: ", "already given on line 1 (as 'alice')"},
      {ok + Line(2, "alice *=query"), "clients.txt:2: ", "name 'alice' already used on line 1"},
      {Line(2, "bob *=query,,panic"), "clients.txt:1: ", "unknown right ''"},
  };
  for (const Case& c : cases) {
    const std::string error = ErrorOf(c.text);
    EXPECT_THAT(error, StartsWith(c.line)) << c.text;
    EXPECT_THAT(error, HasSubstr(c.fragment)) << c.text;
  }
}

TEST(AccessList, RightsPrintAsTheirWords) {
  EXPECT_EQ(Rights::All().ToString(), "command,query,panic");
  EXPECT_EQ((Rights{false, true, true}).ToString(), "query,panic");
  EXPECT_EQ(Rights{}.ToString(), "none");
}

TEST(AccessList, APackageNeedsTheRightsOfWhatItCarries) {
  const AccessList list =
      AccessList::Parse(Line(1, "alice *=all") + Line(2, "monitor *=query pioneer=query,panic"), "c");
  Request commands;
  commands.commands.push_back(Command{.id = 1, .type = CommandType::kPanicReset});
  Request queries;
  queries.queries.push_back(Query{.id = 2});
  Request panic;
  panic.panic = true;
  const Request heartbeat;

  const AccessEntry& alice = *list.Find(Key(1));
  const AccessEntry& monitor = *list.Find(Key(2));
  for (const Request* r : std::initializer_list<const Request*>{&commands, &queries, &panic, &heartbeat}) {
    EXPECT_EQ(CheckRights(list, alice, "pioneer", *r), "");
  }
  EXPECT_EQ(CheckRights(list, monitor, "pioneer", commands),
            "client 'monitor' may not command robot 'pioneer' (its rights there: query,panic)");
  EXPECT_EQ(CheckRights(list, monitor, "pioneer", queries), "");
  EXPECT_EQ(CheckRights(list, monitor, "pioneer", panic), "");
  EXPECT_THAT(CheckRights(list, monitor, "arm", panic), HasSubstr("may not panic robot 'arm'"));
  EXPECT_EQ(CheckRights(list, monitor, "arm", heartbeat), "");
}

class AccessListFile : public ::testing::Test {
 protected:
  void SetUp() override {
    file_ = std::filesystem::temp_directory_path() /
            ("robotalk_acl_test_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove(file_);
  }
  void TearDown() override { std::filesystem::remove(file_); }
  std::filesystem::path file_;
};

TEST_F(AccessListFile, AFileWritableByGroupOrOthersIsRefusedNamingItsMode) {
  { std::ofstream(file_) << Line(1, "alice *=all"); }
  ASSERT_EQ(::chmod(file_.c_str(), 0664), 0);
  try {
    AccessList::ReadFile(file_);
    ADD_FAILURE() << "a group-writable list was accepted";
  } catch (const AccessListError& e) {
    EXPECT_THAT(e.what(), HasSubstr(file_.string()));
    EXPECT_THAT(e.what(), HasSubstr("mode 0664"));
  }
  ASSERT_EQ(::chmod(file_.c_str(), 0644), 0);
  EXPECT_EQ(AccessList::ReadFile(file_).size(), 1U);
}

TEST_F(AccessListFile, ALineErrorNamesThePathAndLine) {
  { std::ofstream(file_) << Line(1, "alice *=all") << Line(2, "bob *=fly"); }
  ASSERT_EQ(::chmod(file_.c_str(), 0644), 0);
  EXPECT_THROW(
      try { AccessList::ReadFile(file_); } catch (const AccessListError& e) {
        EXPECT_THAT(e.what(), StartsWith(file_.string() + ":2: "));
        throw;
      },
      AccessListError);
  EXPECT_THROW(AccessList::ReadFile(file_.string() + ".missing"), AccessListError);
}

// Issue 19 item 12: an access list owned by another user, in a
// world-writable directory or through a symlink was accepted.
class AccessListTrust : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/robotalk_acl_trust_XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    dir_ = pattern;
    file_ = dir_ / "clients";
    { std::ofstream(file_) << Line(1, "alice *=all"); }
    ASSERT_EQ(::chmod(file_.c_str(), 0644), 0);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  // The refusal's text, or "" when the list was accepted.
  std::string Refusal(const std::filesystem::path& file) const {
    try {
      AccessList::ReadFile(file);
      return "";
    } catch (const AccessListError& e) {
      return e.what();
    }
  }
  std::filesystem::path dir_, file_;
};

TEST_F(AccessListTrust, AListOwnedByAnotherUserIsRefusedNamingTheOwner) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to give a file away (chown)";
  ASSERT_EQ(::chown(file_.c_str(), 4242, -1), 0);
  EXPECT_THAT(Refusal(file_), HasSubstr(file_.string() + ": owned by uid 4242"));
  ASSERT_EQ(::chown(file_.c_str(), 0, -1), 0);  // root:root 0644, as documented
  EXPECT_EQ(Refusal(file_), "");
}

TEST_F(AccessListTrust, AListInAWorldWritableDirectoryIsRefused) {
  ASSERT_EQ(::chmod(dir_.c_str(), 0777), 0);
  EXPECT_THAT(Refusal(file_), HasSubstr("directory " + dir_.string() + " (mode 0777) is world-writable"));
  ASSERT_EQ(::chmod(dir_.c_str(), 0755), 0);
  EXPECT_EQ(Refusal(file_), "");
}

TEST_F(AccessListTrust, AListInADirectoryOwnedByAnotherUserIsRefused) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to give a directory away (chown)";
  ASSERT_EQ(::chown(dir_.c_str(), 4242, -1), 0);
  EXPECT_THAT(Refusal(file_), HasSubstr("directory " + dir_.string() + " is owned by uid 4242"));
}

TEST_F(AccessListTrust, AListThroughASymlinkIsRefused) {
  std::filesystem::create_symlink(file_, dir_ / "link");
  EXPECT_THAT(Refusal(dir_ / "link"), HasSubstr((dir_ / "link").string() + ": is a symbolic link"));
}

}  // namespace
}  // namespace robotalk

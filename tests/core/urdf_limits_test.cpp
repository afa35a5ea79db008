// URDF import under hostile or huge input: nesting depth and size limits
// (checked before any XML parser recurses or reads the whole file), and
// merging / mimic flattening that stay linear on long chains. The inputs are
// generated here; issue 9 found a 100,000-deep file crashing the importer.
#include "robotalk/error.h"
#include "robotalk/urdf_import.h"

#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

namespace robotalk {
namespace {

std::string ErrorOf(const std::string& xml, const UrdfImportOptions& options = {}) {
  try {
    ParseUrdf(xml, options, "test.urdf");
  } catch (const UrdfError& e) {
    return e.what();
  }
  return "";
}

std::string Nested(int depth) {
  std::string xml = "<robot name=\"r\"><link name=\"a\"/>";
  for (int i = 0; i < depth; ++i) xml += "<x>";
  for (int i = 0; i < depth; ++i) xml += "</x>";
  return xml + "</robot>";
}

std::string Revolute(const std::string& name, const std::string& parent, const std::string& child,
                     const std::string& extra = "") {
  return "<joint name=\"" + name + "\" type=\"revolute\"><parent link=\"" + parent + "\"/><child link=\"" +
         child + "\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" velocity=\"1\"/>" +
         extra + "</joint>";
}

// l0 -> l1 -> ... -> l<n>, all links massless, joints j0..j<n-1> at zero origin.
std::string MasslessChain(int n) {
  std::string xml = "<robot name=\"chain\">";
  for (int i = 0; i <= n; ++i) xml += "<link name=\"l" + std::to_string(i) + "\"/>";
  for (int i = 0; i < n; ++i) {
    xml += Revolute("j" + std::to_string(i), "l" + std::to_string(i), "l" + std::to_string(i + 1));
  }
  return xml + "</robot>";
}

TEST(UrdfLimits, RefusesA100000DeepDocumentWithTheDepthAndTheLimitInsteadOfCrashing) {
  const std::string message = ErrorOf(Nested(100000));
  EXPECT_NE(message.find("test.urdf: XML elements nested 100001 deep"), std::string::npos) << message;
  EXPECT_NE(message.find("the limit is 100 (UrdfImportOptions::max_xml_depth)"), std::string::npos)
      << message;
}

TEST(UrdfLimits, AcceptsNestingUpToTheLimitAndRefusesOneMore) {
  // <robot> is depth 1, so Nested(3) is 4 deep.
  EXPECT_EQ(ErrorOf(Nested(3), {.max_xml_depth = 4}), "");
  const std::string message = ErrorOf(Nested(4), {.max_xml_depth = 4});
  EXPECT_NE(message.find("nested 5 deep (deeper than 4 from line 1)"), std::string::npos) << message;
}

TEST(UrdfLimits, NamesTheLineWhereTheLimitIsFirstPassed) {
  const std::string xml = "<robot name=\"r\">\n<link name=\"a\"/>\n<x>\n<y>\n<z/></y></x></robot>";
  EXPECT_NE(ErrorOf(xml, {.max_xml_depth = 2}).find("deeper than 2 from line 4"), std::string::npos);
}

TEST(UrdfLimits, DoesNotCountTagsInCommentsCdataDeclarationsOrAttributeValues) {
  const std::string xml =
      "<?xml version=\"1.0\"?><!DOCTYPE robot><robot name=\"r\">"
      "<!-- <x><x><x><x> --><link name=\"a\" note=\"<x><x>\" other='a>b<c>'/>"
      "<gazebo><![CDATA[<x><x><x><x>]]></gazebo><link name=\"b\"/>" +
      Revolute("j", "a", "b") + "</robot>";
  // <robot> <joint> <limit/> is the deepest real nesting: 2 open elements.
  EXPECT_EQ(ErrorOf(xml, {.max_xml_depth = 2}), "");
}

TEST(UrdfLimits, CountsElementsAfterAProcessingInstructionEndsAtItsFirstCloseBracket) {
  // TinyXML ends "<?pi" at the first '>', so the <x>s after it are elements:
  // a scan that skipped to "?>" would let them through unchecked.
  const std::string xml = "<robot name=\"r\"><link name=\"a\"/><?pi ><x><x><x></x></x></x> ?></robot>";
  EXPECT_NE(ErrorOf(xml, {.max_xml_depth = 3}).find("nested 4 deep"), std::string::npos);
}

TEST(UrdfLimits, RefusesTextLongerThanTheSizeLimitBeforeParsingIt) {
  const std::string xml = MasslessChain(3);
  const std::string message = ErrorOf(xml, {.max_file_bytes = 100});
  EXPECT_NE(message.find("test.urdf: " + std::to_string(xml.size()) +
                         " bytes is more than the limit of 100 bytes (UrdfImportOptions::max_file_bytes)"),
            std::string::npos)
      << message;
  EXPECT_EQ(ErrorOf(xml, {.max_file_bytes = xml.size()}), "");
}

class TempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    char pattern[] = "/tmp/urdf_limits_XXXXXX";
    ASSERT_NE(mkdtemp(pattern), nullptr);
    dir_ = pattern;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string dir_;
};

using UrdfLimitsFile = TempDir;

TEST_F(UrdfLimitsFile, RefusesAFileOverTheSizeLimitNamingFileSizeAndLimit) {
  const std::string path = dir_ + "/big.urdf";
  const std::string xml = MasslessChain(20);
  std::ofstream(path) << xml;
  try {
    LoadUrdfFile(path, {.max_file_bytes = 1000});
    FAIL() << "no error";
  } catch (const UrdfError& e) {
    EXPECT_EQ(std::string(e.what()), path + ": " + std::to_string(xml.size()) +
                                         " bytes is more than the limit of 1000 bytes "
                                         "(UrdfImportOptions::max_file_bytes)");
  }
  EXPECT_EQ(LoadUrdfFile(path, {.max_file_bytes = xml.size()}).model.joints().size(), 20u);
}

TEST_F(UrdfLimitsFile, RefusesAPipeThatDeliversMoreThanTheLimit) {
  const std::string path = dir_ + "/fifo.urdf";
  ASSERT_EQ(mkfifo(path.c_str(), 0600), 0);
  const std::string xml = MasslessChain(20);  // a few KB, under the pipe buffer
  std::thread writer([&] { std::ofstream(path) << xml; });
  std::string message;
  try {
    LoadUrdfFile(path, {.max_file_bytes = 1000});
  } catch (const UrdfError& e) {
    message = e.what();
  }
  writer.join();
  EXPECT_EQ(message,
            path + ": the text is longer than the limit of 1000 bytes (UrdfImportOptions::max_file_bytes)");
}

TEST(UrdfLimits, MergesA10000LinkMasslessChainIntoSixDofJointsTopDown) {
  // Before the merge was made linear this took about a minute.
  const UrdfImportResult r = ParseUrdf(MasslessChain(10000), {.merge_massless_chains = true});
  ASSERT_EQ(r.model.joints().size(), 1667u);  // ceil(10000 / 6)
  EXPECT_EQ(r.model.links().size(), 1668u);
  EXPECT_EQ(r.model.joint(0).name, "j0+j1+j2+j3+j4+j5");
  EXPECT_EQ(r.model.joint(0).dofs.size(), 6u);
  EXPECT_EQ(r.model.joint(1).name, "j6+j7+j8+j9+j10+j11");
  EXPECT_EQ(r.model.joint(1666).name, "j9996+j9997+j9998+j9999");
  EXPECT_EQ(r.model.link(r.model.joint(1666).child_link).name, "l10000");
  EXPECT_EQ(r.model.num_dofs(), 10000);
}

TEST(UrdfLimits, FlattensALongChainOfMimicsWithOneWarningEach) {
  // j<k> mimics j<k-1> with offset 1, so after flattening j<k> = q(j0) + k.
  const int n = 2000;
  std::string xml = "<robot name=\"m\"><link name=\"base\"/>";
  for (int k = 0; k < n; ++k) xml += "<link name=\"c" + std::to_string(k) + "\"/>";
  for (int k = 0; k < n; ++k) {
    xml += Revolute("j" + std::to_string(k), "base", "c" + std::to_string(k),
                    k == 0 ? "" : "<mimic joint=\"j" + std::to_string(k - 1) + "\" offset=\"1\"/>");
  }
  const UrdfImportResult r = ParseUrdf(xml + "</robot>");
  for (int k : {1, 2, 1000, n - 1}) {
    ASSERT_TRUE(r.model.joint(k).mimic.has_value()) << k;
    EXPECT_EQ(*r.model.joint(k).mimic, (Mimic{.leader_joint = 0, .multiplier = 1, .offset = double(k)})) << k;
  }
  EXPECT_EQ(r.warnings.size(), static_cast<size_t>(n - 2));  // j1 follows j0 directly
}

TEST(UrdfLimits, DropsEveryMimicOnOrIntoALongCycleWithOneWarningEach) {
  // j0 -> j1 -> ... -> j<n-1> -> j0, and a tail t -> j5 leading into it.
  const int n = 2000;
  std::string xml = "<robot name=\"m\"><link name=\"base\"/><link name=\"ct\"/>";
  for (int k = 0; k < n; ++k) xml += "<link name=\"c" + std::to_string(k) + "\"/>";
  xml += Revolute("t", "base", "ct", "<mimic joint=\"j5\"/>");
  for (int k = 0; k < n; ++k) {
    xml += Revolute("j" + std::to_string(k), "base", "c" + std::to_string(k),
                    "<mimic joint=\"j" + std::to_string((k + 1) % n) + "\"/>");
  }
  const UrdfImportResult r = ParseUrdf(xml + "</robot>");
  for (const Joint& j : r.model.joints()) EXPECT_FALSE(j.mimic.has_value()) << j.name;
  ASSERT_EQ(r.warnings.size(), static_cast<size_t>(n + 1));
  EXPECT_NE(
      std::find(r.warnings.begin(), r.warnings.end(), "joint 't': mimic joints form a cycle; mimic dropped"),
      r.warnings.end());
}

}  // namespace
}  // namespace robotalk

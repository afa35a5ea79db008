// robotalk-web's mesh resolution (tools/web/mesh_catalog.h, issue 21): a
// URDF's package://, relative and absolute mesh names become files the
// bridge serves, only from below the package paths and the URDF's folder;
// a name that climbs out (../, a symbolic link) is refused naming the path;
// an unknown package names the folders searched.
#include "mesh_catalog.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace robotalk::web {
namespace {

namespace fs = std::filesystem;

class MeshCatalogTest : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("mesh_catalog_test_" + std::to_string(::getpid()) + "_" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    Write("ws/src/arm_description/package.xml", "<package><name>arm_description</name></package>");
    Write("ws/src/arm_description/meshes/link1.stl", "solid a\nendsolid a\n");
    Write("ws/src/renamed_dir/package.xml", "<package><name>gripper</name></package>");
    Write("ws/src/renamed_dir/meshes/finger.dae", "<COLLADA/>");
    Write("robot/meshes/base.stl", "solid b\nendsolid b\n");
    Write("secret/key.stl", "not yours");
    fs::create_directory_symlink(root_ / "secret", root_ / "ws/src/arm_description/escape");
  }
  void TearDown() override { fs::remove_all(root_); }

  void Write(const std::string& rel, const std::string& text) {
    fs::create_directories((root_ / rel).parent_path());
    std::ofstream(root_ / rel) << text;
  }

  // A URDF in robot/ with one link per mesh filename, its <visual> and its
  // <collision> both naming it.
  MeshCatalog Resolve(const std::vector<std::string>& filenames, const std::vector<std::string>& paths) {
    std::string xml = "<robot name=\"r\">";
    for (std::size_t i = 0; i < filenames.size(); ++i) {
      xml += "<link name=\"l" + std::to_string(i) + "\"><visual><geometry><mesh filename=\"" + filenames[i] +
             "\"/></geometry></visual><collision><geometry><mesh filename=\"" + filenames[i] +
             "\"/></geometry></collision></link>";
    }
    Write("robot/r.urdf", xml + "</robot>");
    return ResolveMeshes("r", (root_ / "robot/r.urdf").string(), paths);
  }

  fs::path root_;
};

TEST_F(MeshCatalogTest, FindsPackagesByTheirPackageXmlBelowTheRoots) {
  const auto packages = FindPackages({(root_ / "ws").string(), (root_ / "missing").string()});
  ASSERT_TRUE(packages.count("arm_description"));
  EXPECT_EQ(packages.at("arm_description"), fs::canonical(root_ / "ws/src/arm_description"));
  ASSERT_TRUE(packages.count("gripper")) << "the name in package.xml, not the folder's";
  EXPECT_EQ(packages.at("gripper"), fs::canonical(root_ / "ws/src/renamed_dir"));
  // A root that is itself the package.
  EXPECT_EQ(FindPackages({(root_ / "ws/src/renamed_dir").string()}).count("gripper"), 1u);
}

TEST_F(MeshCatalogTest, ResolvesPackageRelativeAndAbsoluteNamesToServedUrls) {
  const MeshCatalog c =
      Resolve({"package://arm_description/meshes/link1.stl", "package://gripper/meshes/finger.dae",
               "meshes/base.stl", "file://" + (root_ / "robot/meshes/base.stl").string()},
              {(root_ / "ws").string()});
  ASSERT_EQ(c.meshes.size(), 8u) << "the visuals, then the collisions";
  for (const MeshEntry& m : c.meshes) EXPECT_EQ(m.error, "") << m.uri;
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(c.meshes[i].collision, i >= 4) << i;
  EXPECT_EQ(c.meshes[4].link, "l0");
  EXPECT_EQ(c.meshes[4].url, "/mesh/r/4/link1.stl");
  EXPECT_EQ(c.meshes[4].file, c.meshes[0].file);
  EXPECT_EQ(c.shapes.size(), 0u) << "four links without joints: urdfdom refuses the tree";
  EXPECT_NE(c.geometry_error, "");
  EXPECT_EQ(c.meshes[0].link, "l0");
  EXPECT_EQ(c.meshes[0].url, "/mesh/r/0/link1.stl");
  EXPECT_EQ(c.meshes[1].file, fs::canonical(root_ / "ws/src/renamed_dir/meshes/finger.dae"));
  EXPECT_EQ(c.meshes[2].url, "/mesh/r/2/base.stl");
  EXPECT_EQ(c.unresolved(), 0u);
  // What /mesh/r/INDEX/NAME serves: that file, under its own name only.
  EXPECT_EQ(c.File("0/link1.stl"), fs::canonical(root_ / "ws/src/arm_description/meshes/link1.stl"));
  EXPECT_EQ(c.File("0/base.stl"), std::nullopt);
  EXPECT_EQ(c.File("9/link1.stl"), std::nullopt);
  EXPECT_EQ(c.File("x/link1.stl"), std::nullopt);
  // A file beside the mesh (a glTF's .bin), never one outside its folder.
  Write("ws/src/arm_description/meshes/link1.bin", "bin");
  EXPECT_EQ(c.File("0/link1.bin"), fs::canonical(root_ / "ws/src/arm_description/meshes/link1.bin"));
  EXPECT_EQ(c.File("0/../package.xml"), std::nullopt);
  EXPECT_EQ(c.File("0/nope.bin"), std::nullopt);
  Write("ws/src/arm_description/meshes/.hidden", "secret");  // review of issue 20: no hidden files
  EXPECT_EQ(c.File("0/.hidden"), std::nullopt);
  EXPECT_EQ(c.Json()["meshes"][0]["url"], "/mesh/r/0/link1.stl");
}

TEST_F(MeshCatalogTest, RefusesNamesThatLeaveThePackagePathsAndTheUrdfFolder) {
  const MeshCatalog c =
      Resolve({"package://arm_description/../../../secret/key.stl", "../secret/key.stl",
               "package://arm_description/escape/key.stl", (root_ / "secret/key.stl").string()},
              {(root_ / "ws").string()});
  ASSERT_EQ(c.meshes.size(), 8u);
  for (const MeshEntry& m : c.meshes) {
    EXPECT_EQ(m.url, "") << m.uri;
    EXPECT_TRUE(m.file.empty()) << m.uri;
    EXPECT_NE(m.error.find("refused: "), std::string::npos) << m.error;
    EXPECT_NE(m.error.find("is outside the package paths and the URDF's folder"), std::string::npos)
        << m.error;
    EXPECT_NE(m.error.find((fs::canonical(root_) / "secret/key.stl").string()), std::string::npos)
        << "names the file it resolved to: " << m.error;
  }
  EXPECT_EQ(c.Json()["meshes"][0]["url"], nullptr);
  EXPECT_EQ(c.File("0/key.stl"), std::nullopt);
}

TEST_F(MeshCatalogTest, SaysWhichPackageIsMissingAndWhereItLooked) {
  const MeshCatalog none = Resolve({"package://drake_models/iiwa/link_1.obj"}, {});
  EXPECT_EQ(none.meshes.at(0).error,
            "package 'drake_models' not found in the package paths (none given) (give its parent folder with "
            "--package-path or ROS_PACKAGE_PATH)");
  const std::string ws = (root_ / "ws").string();
  const MeshCatalog c =
      Resolve({"package://drake_models/iiwa/link_1.obj", "package://arm_description/meshes/nope.stl",
               "package://", "https://example.com/x.stl"},
              {ws});
  EXPECT_EQ(c.meshes[0].error, "package 'drake_models' not found in the package paths " + ws +
                                   " (give its parent folder with --package-path or ROS_PACKAGE_PATH)");
  EXPECT_EQ(
      c.meshes[1].error,
      "no such file: " + (fs::canonical(root_ / "ws/src/arm_description") / "meshes/nope.stl").string());
  EXPECT_EQ(c.meshes[2].error, "not a package://PACKAGE/PATH");
  EXPECT_EQ(c.meshes[3].error,
            "scheme of 'https://example.com/x.stl' not supported (package://, file://, or a path)");
  EXPECT_EQ(c.unresolved(), 8u);
}

TEST_F(MeshCatalogTest, ReadsTheShapesAndFindsEachMeshShapesEntry) {
  Write("robot/arm.urdf",
        "<robot name='arm'><material name='blue'><color rgba='0 0 1 1'/></material>"
        "<link name='base'><visual><geometry><box size='1 2 3'/></geometry><material name='blue'/></visual>"
        "<collision><origin xyz='0 0 0.5'/><geometry><cylinder radius='0.1' "
        "length='0.4'/></geometry></collision>"
        "</link><link name='tip'><collision><geometry><mesh filename='meshes/base.stl' scale='2 2 2'/>"
        "</geometry></collision></link><joint name='j' type='fixed'><parent link='base'/><child link='tip'/>"
        "</joint></robot>");
  const MeshCatalog c = ResolveMeshes("arm", (root_ / "robot/arm.urdf").string(), {});
  ASSERT_EQ(c.geometry_error, "");
  ASSERT_EQ(c.shapes.size(), 3u);
  EXPECT_EQ(c.shapes[0].kind, UrdfShape::Kind::kBox);
  EXPECT_FALSE(c.shapes[0].collision);
  ASSERT_TRUE(c.shapes[0].rgba.has_value()) << "the robot-level material the visual names";
  EXPECT_EQ(*c.shapes[0].rgba, Eigen::Vector4d(0, 0, 1, 1));
  EXPECT_EQ(c.shapes[1].kind, UrdfShape::Kind::kCylinder);
  EXPECT_TRUE(c.shapes[1].collision);
  EXPECT_EQ(c.shapes[1].size, Eigen::Vector3d(0.1, 0.4, 0));
  EXPECT_EQ(c.shapes[1].origin.translation, Eigen::Vector3d(0, 0, 0.5));
  EXPECT_EQ(c.MeshOf(c.shapes[1]), nullptr);
  ASSERT_NE(c.MeshOf(c.shapes[2]), nullptr);
  EXPECT_EQ(c.MeshOf(c.shapes[2])->file, fs::canonical(root_ / "robot/meshes/base.stl"));
  EXPECT_EQ(c.shapes[2].size, Eigen::Vector3d(2, 2, 2));
}

TEST_F(MeshCatalogTest, AnUnreadableUrdfIsAnErrorNotAThrow) {
  const MeshCatalog c = ResolveMeshes("r", (root_ / "none.urdf").string(), {});
  EXPECT_NE(c.error.find("cannot read the URDF"), std::string::npos) << c.error;
  EXPECT_TRUE(c.meshes.empty());
}

}  // namespace
}  // namespace robotalk::web

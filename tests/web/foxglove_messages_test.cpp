// Tests of the Foxglove channels robotalk-web publishes live and
// robotalk-logplay export --mcap writes (foxglove_messages.h).
#include "foxglove_messages.h"

#include "mesh_catalog.h"
#include "robotalk/error.h"
#include "robotalk/urdf_import.h"
#include "scene_json.h"
#include "test_paths.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

namespace robotalk::web::foxglove {
namespace {

std::shared_ptr<const RobotModel> Pioneer() {
  return std::make_shared<const RobotModel>(
      LoadUrdfFile(testing::ProjectModel("pioneer2dx_pantilt.urdf")).model);
}

nlohmann::json PoseOf(const RobotModel& m, double pan, double x, double theta) {
  StateSample s;
  s.robot = m.name();
  s.sample = 3;
  s.server_time = TimePoint(std::chrono::microseconds(1'700'000'000'123'456));
  s.period = std::chrono::microseconds(10'000);
  s.positions.assign(static_cast<std::size_t>(m.num_dofs()), 0.0);
  s.positions[0] = pan;
  s.velocities.assign(s.positions.size(), 0.0);
  s.efforts.assign(s.positions.size(), 0.0);
  s.base = {.x = x, .y = 0, .theta = theta};
  StatePoser poser(m);
  return poser.Pose(s);
}

Eigen::Isometry3d Iso(const nlohmann::json& t) {
  Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
  x.translation() << t["translation"]["x"], t["translation"]["y"], t["translation"]["z"];
  x.linear() =
      Eigen::Quaterniond(t["rotation"]["w"], t["rotation"]["x"], t["rotation"]["y"], t["rotation"]["z"])
          .toRotationMatrix();
  return x;
}

TEST(FoxgloveSchemas, AreJsonSchemaObjectsNamedAsFoxgloveNamesThem) {
  const std::map<Topic, std::string> names = {{Topic::kTransforms, "foxglove.FrameTransforms"},
                                              {Topic::kScene, "foxglove.SceneUpdate"},
                                              {Topic::kJointStates, "robotalk.JointState"},
                                              {Topic::kBasePose, "foxglove.PoseInFrame"},
                                              {Topic::kStatus, "robotalk.RobotStatus"}};
  for (Topic t : kRobotTopics) {
    EXPECT_EQ(SchemaOf(t).name, names.at(t));
    const auto schema = nlohmann::json::parse(SchemaOf(t).schema);
    EXPECT_EQ(schema["type"], "object");
    EXPECT_TRUE(schema["properties"].is_object());
  }
  EXPECT_EQ(TopicName("arm", Topic::kJointStates), "/arm/joint_states");
  EXPECT_EQ(TimeJson(1'500'000'000'000'000'007), (nlohmann::json{{"sec", 1'500'000'000}, {"nsec", 7}}));
  EXPECT_EQ(TimeJson(-5), (nlohmann::json{{"sec", 0}, {"nsec", 0}}));
}

TEST(RobotMessages, TransformsComposeToTheWorldPosesOfEveryLink) {
  const auto model = Pioneer();
  const RobotMessages m(model);
  const nlohmann::json pose = PoseOf(*model, 0.5, 1.0, 0.3);
  const RobotMessages::State s = m.FromPose(pose);
  EXPECT_EQ(s.time_ns, 1'700'000'000'123'456'000);
  std::map<std::string, std::pair<std::string, Eigen::Isometry3d>> parent;
  for (const auto& t : s.transforms["transforms"])
    parent[t["child_frame_id"]] = {t["parent_frame_id"], Iso(t)};
  for (std::size_t l = 0; l < model->links().size(); ++l) {
    Eigen::Isometry3d world = Eigen::Isometry3d::Identity();
    std::string frame = m.LinkFrame(l);
    for (int hops = 0; frame != "world"; ++hops) {
      ASSERT_LT(hops, 100) << "no path to world from " << m.LinkFrame(l);
      ASSERT_TRUE(parent.count(frame)) << frame << " has no transform";
      world = parent[frame].second * world;
      frame = parent[frame].first;
    }
    const auto& p = pose["links"][l];
    EXPECT_NEAR(world.translation().x(), p[0].get<double>(), 1e-5) << m.LinkFrame(l);
    EXPECT_NEAR(world.translation().y(), p[1].get<double>(), 1e-5) << m.LinkFrame(l);
    EXPECT_NEAR(world.translation().z(), p[2].get<double>(), 1e-5) << m.LinkFrame(l);
  }
  EXPECT_EQ(s.joint_states["name"], DofNames(*model));
  EXPECT_EQ(s.joint_states["position"][0], 0.5);
  EXPECT_EQ(s.base_pose["frame_id"], "world");
  EXPECT_NEAR(s.base_pose["pose"]["position"]["x"].get<double>(), 1.0, 1e-6);
  EXPECT_EQ(s.status["panic"], false);
  EXPECT_EQ(s.status["sample"], 3);
}

TEST(RobotMessages, SceneHasAnEntityPerLinkLockedToItsFrame) {
  const auto model = Pioneer();
  const RobotMessages m(model);
  const nlohmann::json scene = m.Scene(42);
  ASSERT_EQ(scene["entities"].size(), model->links().size());
  ASSERT_EQ(scene["deletions"].size(), 1u);  // the previous model's entities, all of them
  EXPECT_EQ(scene["deletions"][0]["type"], 1);
  for (std::size_t l = 0; l < model->links().size(); ++l) {
    const auto& e = scene["entities"][l];
    EXPECT_EQ(e["frame_id"], model->name() + "/" + model->links()[l].name);
    EXPECT_TRUE(e["frame_locked"].get<bool>());
    EXPECT_EQ(e["cubes"].size(), 1u);
    EXPECT_EQ(e["timestamp"]["nsec"], 42);
    EXPECT_EQ(e["metadata"][0]["key"], "geometry");
    EXPECT_EQ(e["metadata"][0]["value"], "inertia box") << "without a URDF the scene says what it shows";
  }
}

std::string Meta(const nlohmann::json& entity, const std::string& key) {
  for (const auto& kv : entity["metadata"])
    if (kv["key"] == key) return kv["value"];
  return "";
}

// Every link of a URDF robot is drawn from the URDF: its <collision> shapes
// (its <visual> ones when it has no <collision>), one primitive each, a mesh
// as a model when it resolves and the inertia box beside a note when not.
void ExpectSceneIsTheUrdfGeometry(const std::string& path, const std::vector<std::string>& package_paths) {
  SCOPED_TRACE(path);
  const auto model = std::make_shared<const RobotModel>(LoadUrdfFile(path).model);
  const MeshCatalog catalog = ResolveMeshes(model->name(), path, package_paths);
  ASSERT_EQ(catalog.error, "");
  ASSERT_FALSE(catalog.shapes.empty());
  const nlohmann::json scene = RobotMessages(model, catalog).Scene(7, {.url_base = "http://h:1"});
  ASSERT_EQ(scene["entities"].size(), model->links().size());
  std::size_t primitives = 0;
  for (std::size_t l = 0; l < model->links().size(); ++l) {
    const std::string& link = model->links()[l].name;
    const nlohmann::json& e = scene["entities"][l];
    SCOPED_TRACE(link);
    EXPECT_EQ(e["frame_id"], model->name() + "/" + link);
    std::map<UrdfShape::Kind, std::size_t> want;
    std::size_t unresolved = 0;
    bool collision = false;
    for (const UrdfShape& s : catalog.shapes) collision = collision || (s.link == link && s.collision);
    for (const UrdfShape& s : catalog.shapes) {
      if (s.link != link || s.collision != collision) continue;
      if (s.kind == UrdfShape::Kind::kMesh && catalog.MeshOf(s)->url.empty()) {
        ++unresolved;
      } else {
        ++want[s.kind];
      }
    }
    EXPECT_EQ(e["cubes"].size(), want[UrdfShape::Kind::kBox] + (unresolved ? 1 : 0));
    EXPECT_EQ(e["cylinders"].size(), want[UrdfShape::Kind::kCylinder]);
    EXPECT_EQ(e["spheres"].size(), want[UrdfShape::Kind::kSphere]);
    EXPECT_EQ(e["models"].size(), want[UrdfShape::Kind::kMesh]);
    for (const auto& m : e["models"]) {
      EXPECT_EQ(m["url"].get<std::string>().rfind("http://h:1/mesh/" + model->name() + "/", 0), 0u) << m;
    }
    if (unresolved) {
      EXPECT_NE(Meta(e, "mesh"), "") << "an unresolved mesh is named with its reason";
    }
    primitives += e["cubes"].size() + e["cylinders"].size() + e["spheres"].size() + e["models"].size();
  }
  EXPECT_GT(primitives, 0u);
}

TEST(RobotMessages, SceneOfAUrdfIsItsCollisionGeometry) {
  ExpectSceneIsTheUrdfGeometry(testing::ProjectModel("pioneer2dx_pantilt.urdf"), {});
  ExpectSceneIsTheUrdfGeometry(testing::ProjectModel("simple_humanoid.urdf"), {});
  const std::string web_data = std::string(ROBOTALK_MODELS_DIR) + "/../tests/web/data";
  ExpectSceneIsTheUrdfGeometry(web_data + "/mesh_bot/urdf/mesh_bot.urdf", {web_data});
}

TEST(RobotMessages, SceneOfTheSharedRobotsIsTheirUrdfGeometry) {
  ROBOTALK_REQUIRE_SHARED_ROBOTS();
  for (const char* robot : {"ur5.urdf", "iiwa14.urdf", "pr2.urdf", "atlas.urdf", "pioneer3dx.urdf"})
    ExpectSceneIsTheUrdfGeometry(testing::SharedRobot(robot), {});
}

TEST(RobotMessages, SceneOfPioneerHasItsBoxesCylindersAndSphere) {
  const std::string path = testing::ProjectModel("pioneer2dx_pantilt.urdf");
  const auto model = std::make_shared<const RobotModel>(LoadUrdfFile(path).model);
  const nlohmann::json scene = RobotMessages(model, ResolveMeshes("pioneer", path, {})).Scene(0, {});
  std::map<std::string, nlohmann::json> by_link;
  for (const auto& e : scene["entities"]) by_link[e["id"]] = e;
  const std::string p = model->name() + "/";
  const auto& base = by_link.at(p + "base_link")["cubes"].at(0);
  EXPECT_EQ(base["size"], (nlohmann::json{{"x", 0.44}, {"y", 0.38}, {"z", 0.22}}));
  EXPECT_EQ(base["pose"]["position"], (nlohmann::json{{"x", -0.1}, {"y", 0.0}, {"z", 0.17}}));
  EXPECT_EQ(Meta(by_link.at(p + "base_link"), "geometry"), "urdf collision");
  const auto& wheel = by_link.at(p + "left_wheel")["cylinders"].at(0);
  EXPECT_EQ(wheel["size"], (nlohmann::json{{"x", 0.195}, {"y", 0.195}, {"z", 0.05}}));
  EXPECT_NEAR(wheel["pose"]["orientation"]["x"].get<double>(), std::sqrt(0.5), 1e-6);
  const auto& caster = by_link.at(p + "caster")["spheres"].at(0);
  EXPECT_EQ(caster["size"], (nlohmann::json{{"x", 0.075}, {"y", 0.075}, {"z", 0.075}}));
  EXPECT_EQ(Meta(by_link.at(p + "ptu_base"), "geometry"), "urdf visual") << "no <collision>: its <visual>";
}

TEST(RobotMessages, SceneEmbedsAResolvedMeshWhenAskedAndLinksItOtherwise) {
  const std::string web_data = std::string(ROBOTALK_MODELS_DIR) + "/../tests/web/data";
  const std::string path = web_data + "/mesh_bot/urdf/mesh_bot.urdf";
  const auto model = std::make_shared<const RobotModel>(LoadUrdfFile(path).model);
  const RobotMessages m(model, ResolveMeshes(model->name(), path, {web_data}));
  std::map<std::string, nlohmann::json> linked, embedded;
  const nlohmann::json live = m.Scene(0, {.url_base = "http://127.0.0.1:8080"});
  const nlohmann::json recorded = m.Scene(0, {.embed = true});
  for (const auto& e : live["entities"]) linked[e["id"]] = e;
  for (const auto& e : recorded["entities"]) embedded[e["id"]] = e;
  const auto& arm = linked.at("mesh_bot/arm")["models"].at(0);
  EXPECT_EQ(arm["url"], "http://127.0.0.1:8080/mesh/mesh_bot/1/arm.stl");
  EXPECT_EQ(arm["media_type"], "model/stl");
  EXPECT_EQ(arm["data"], "");
  const auto& packed = embedded.at("mesh_bot/arm")["models"].at(0);
  EXPECT_EQ(packed["url"], "");
  EXPECT_EQ(packed["media_type"], "model/stl");
  EXPECT_FALSE(packed["data"].get<std::string>().empty());
  EXPECT_EQ(Meta(embedded.at("mesh_bot/arm"), "geometry"), "urdf visual") << "mesh_bot has no <collision>";
  // tool's package is missing: its inertia box, and why.
  const auto& tool = linked.at("mesh_bot/tool");
  EXPECT_EQ(tool["cubes"].size(), 1u);
  EXPECT_NE(Meta(tool, "mesh").find("missing_pkg"), std::string::npos) << tool;
}

TEST(RobotMessages, AMeshOverTheEmbeddingLimitIsDrawnAsItsInertiaBoxSayingWhy) {
  const std::string web_data = std::string(ROBOTALK_MODELS_DIR) + "/../tests/web/data";
  const std::string path = web_data + "/mesh_bot/urdf/mesh_bot.urdf";
  const auto model = std::make_shared<const RobotModel>(LoadUrdfFile(path).model);
  const RobotMessages m(model, ResolveMeshes(model->name(), path, {web_data}));
  std::map<std::string, nlohmann::json> by_id;
  const nlohmann::json scene = m.Scene(0, {.embed = true, .max_embedded_bytes = 16});
  for (const auto& e : scene["entities"]) by_id[e["id"]] = e;
  const auto& arm = by_id.at("mesh_bot/arm");
  EXPECT_TRUE(arm["models"].empty()) << arm;
  EXPECT_EQ(arm["cubes"].size(), 1u);
  EXPECT_NE(Meta(arm, "mesh").find("over the 16-byte limit of an embedded mesh"), std::string::npos) << arm;
}

// A STATE sample's time at the wire's extremes (a forged sample, a damaged
// log exported to MCAP) is stamped at those extremes: its seconds, back in
// microseconds, round up past them, and the nanoseconds overflowed an int64
// (review 10: undefined behaviour; it wrapped to the far side of the range).
TEST(RobotMessages, AStateAtTheWiresExtremeTimesIsStampedThereWithoutOverflow) {
  const auto model = Pioneer();
  const RobotMessages m(model);
  StatePoser poser(*model);
  for (const std::int64_t us : {kMaxWireMicros, -kMaxWireMicros}) {
    StateSample s;
    s.robot = model->name();
    s.server_time = FromWireMicros(us);
    s.period = std::chrono::microseconds(10'000);
    s.positions.assign(static_cast<std::size_t>(model->num_dofs()), 0.0);
    s.velocities = s.efforts = s.positions;
    EXPECT_EQ(m.FromPose(poser.Pose(s)).time_ns, us * 1000) << us;
  }
}

TEST(RobotMessages, FromPoseOfAnotherModelThrowsNamingTheRobot) {
  const auto model = Pioneer();
  const RobotMessages m(model);
  nlohmann::json pose = PoseOf(*model, 0, 0, 0);
  pose["links"].erase(0);
  try {
    m.FromPose(pose);
    FAIL() << "no throw";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(model->name()), std::string::npos) << e.what();
  }
  pose.erase("t");
  EXPECT_THROW(m.FromPose(pose), Error);
}

TEST(RobotMessages, SceneRefersToAGltfByItsFileEvenWhenEmbedding) {
  // A .gltf names its buffers beside it: embedded alone it would not load.
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("foxglove_gltf_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  std::ofstream(dir / "part.gltf") << "{}";
  std::ofstream(dir / "r.urdf")
      << "<robot name='r'><link name='a'><inertial><mass value='1'/><inertia ixx='1' "
         "ixy='0' ixz='0' iyy='1' iyz='0' izz='1'/></inertial><collision><geometry>"
         "<mesh filename='part.gltf'/></geometry></collision></link></robot>";
  const std::string path = (dir / "r.urdf").string();
  const auto model = std::make_shared<const RobotModel>(LoadUrdfFile(path).model);
  const nlohmann::json scene = RobotMessages(model, ResolveMeshes("r", path, {})).Scene(0, {.embed = true});
  const auto& m = scene["entities"].at(0)["models"].at(0);
  EXPECT_EQ(m["url"], "file://" + fs::canonical(dir / "part.gltf").string());
  EXPECT_EQ(m["data"], "");
  EXPECT_EQ(m["media_type"], "model/gltf+json");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace robotalk::web::foxglove

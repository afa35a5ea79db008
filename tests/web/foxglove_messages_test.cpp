// Tests of the Foxglove channels robotalk-web publishes live and
// robotalk-logplay export --mcap writes (foxglove_messages.h).
#include "foxglove_messages.h"

#include "robotalk/error.h"
#include "robotalk/urdf_import.h"
#include "scene_json.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <cmath>
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

}  // namespace
}  // namespace robotalk::web::foxglove

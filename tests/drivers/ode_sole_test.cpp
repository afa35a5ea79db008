// A walking humanoid's soles found from its model (issue 26, item 5):
// drivers/ode_sim/collision_shapes.h's FindSole derives a foot's sole from
// a box or from its contact points (Drake's models give a foot eight
// spheres of radius 0), WalkingHumanoid::SoleSpringFor scales the soles'
// contact spring to the model, and WalkingHumanoid::Create accepts a
// synthetic point-footed humanoid with its gait geometry from the points and
// refuses, saying why, a foot that has no sole. Pure: no ODE stepping, no
// ../shared.
#include "collision_shapes.h"
#include "ode_driver.h"
#include "point_footed_humanoid.h"
#include "robotalk/urdf_import.h"
#include "test_paths.h"
#include "walking_humanoid.h"

#include <gtest/gtest.h>

#include <cmath>

namespace robotalk {
namespace {

using ode_detail::WalkingHumanoid;
using testing::ContactPoint;
using testing::PointFootedHumanoid;
using testing::SixPointSoles;
using testing::TempUrdf;

CollisionShape Sphere(const std::string& link, double x, double y, double z, double radius = 0) {
  CollisionShape s;
  s.link = link;
  s.kind = CollisionShape::Kind::kSphere;
  s.size = Eigen::Vector3d(radius, 0, 0);
  s.origin.translation = Eigen::Vector3d(x, y, z);
  return s;
}

CollisionShape Box(const std::string& link, Eigen::Vector3d size, Eigen::Vector3d at) {
  CollisionShape s;
  s.link = link;
  s.kind = CollisionShape::Kind::kBox;
  s.size = size;
  s.origin.translation = at;
  return s;
}

// Atlas's left foot (atlas_minimal_contact): eight points of radius 0 at
// z = -0.07645, x in {-0.0876, -0.0008, 0.086, 0.1728}, y in {0.066, -0.0626}.
std::vector<CollisionShape> AtlasLikeFoot(const std::string& link) {
  std::vector<CollisionShape> shapes;
  for (double x : {-0.0876, -0.0008, 0.086, 0.1728}) {
    for (double y : {0.066, -0.0626}) shapes.push_back(Sphere(link, x, y, -0.07645));
  }
  return shapes;
}

TEST(SoleFromModel, EightContactPointsGiveTheirBoundingRectangleAtTheLowestHeight) {
  std::vector<CollisionShape> shapes = AtlasLikeFoot("l_foot");
  shapes.push_back(Sphere("l_foot", 0.3, 0.3, 0.0, 0.01));  // a bumper above the sole: not the sole
  shapes.push_back(Sphere("r_foot", -1.0, -1.0, -1.0));     // another link's point: ignored
  shapes.push_back(Box("pelvis", {1, 1, 1}, {0, 0, -2}));   // another link's box: ignored
  std::string why;
  const std::optional<Sole> s = FindSole("l_foot", shapes, &why);
  ASSERT_TRUE(s.has_value()) << why;
  EXPECT_TRUE(s->from_points);
  EXPECT_EQ(s->contacts, 8);
  EXPECT_DOUBLE_EQ(s->front, 0.1728);
  EXPECT_DOUBLE_EQ(s->back, 0.0876);
  EXPECT_DOUBLE_EQ(s->left, 0.066);
  EXPECT_DOUBLE_EQ(s->right, 0.0626);
  EXPECT_DOUBLE_EQ(s->z, -0.07645);
  // As a box: the same rectangle, `thickness` above the sole plane.
  const CollisionShape box = s->Box("l_foot", 0.02);
  EXPECT_EQ(box.kind, CollisionShape::Kind::kBox);
  const std::optional<Sole> again = FindSole("l_foot", {box}, &why);
  ASSERT_TRUE(again.has_value()) << why;
  EXPECT_NEAR(again->front, s->front, 1e-12);
  EXPECT_NEAR(again->back, s->back, 1e-12);
  EXPECT_NEAR(again->left, s->left, 1e-12);
  EXPECT_NEAR(again->right, s->right, 1e-12);
  EXPECT_NEAR(again->z, s->z, 1e-12);
  EXPECT_EQ(again->contacts, 4);
}

TEST(SoleFromModel, ASpheresLowestPointIsItsContactAndPointsJustAboveTheLowestCount) {
  std::vector<CollisionShape> shapes;
  // Four spheres of radius 1 cm whose lowest points are at -0.10, one of
  // them 0.5 mm higher (within kSoleFlatness), one 5 mm higher (not).
  shapes.push_back(Sphere("foot", 0.10, 0.05, -0.09, 0.01));
  shapes.push_back(Sphere("foot", 0.10, -0.05, -0.09, 0.01));
  shapes.push_back(Sphere("foot", -0.05, 0.05, -0.09, 0.01));
  shapes.push_back(Sphere("foot", -0.05, -0.05, -0.0895, 0.01));
  shapes.push_back(Sphere("foot", -0.20, 0.0, -0.085, 0.01));
  std::string why;
  const std::optional<Sole> s = FindSole("foot", shapes, &why);
  ASSERT_TRUE(s.has_value()) << why;
  EXPECT_EQ(s->contacts, 4);
  EXPECT_DOUBLE_EQ(s->z, -0.10);
  EXPECT_DOUBLE_EQ(s->back, 0.05) << "the higher point at x = -0.20 is not part of the sole";
  EXPECT_DOUBLE_EQ(s->front, 0.10);
}

TEST(SoleFromModel, ABoxIsItsBottomFace) {
  // models/simple_humanoid.urdf's foot.
  std::string why;
  const std::optional<Sole> s =
      FindSole("left_foot", {Box("left_foot", {0.24, 0.12, 0.05}, {0.03, 0, -0.045})}, &why);
  ASSERT_TRUE(s.has_value()) << why;
  EXPECT_FALSE(s->from_points);
  EXPECT_DOUBLE_EQ(s->front, 0.15);
  EXPECT_DOUBLE_EQ(s->back, 0.09);
  EXPECT_DOUBLE_EQ(s->left, 0.06);
  EXPECT_DOUBLE_EQ(s->right, 0.06);
  EXPECT_DOUBLE_EQ(s->z, -0.07);
  EXPECT_EQ(s->contacts, 4);
  EXPECT_DOUBLE_EQ(s->left + s->right, WalkingHumanoid::kSoleTunedWidth);
}

TEST(SoleFromModel, AFootWithoutASoleSaysWhy) {
  std::string why;
  EXPECT_FALSE(FindSole("foot", {Box("shin", {0.1, 0.1, 0.1}, {0, 0, 0})}, &why).has_value());
  EXPECT_EQ(
      why,
      "foot 'foot' has no box collision shape (a sole) and no contact points (spheres) to derive one from");
  // Points in a line (a blade, not a sole).
  why.clear();
  EXPECT_FALSE(
      FindSole("foot", {Sphere("foot", -0.1, 0, 0), Sphere("foot", 0, 0, 0), Sphere("foot", 0.1, 0, 0)}, &why)
          .has_value());
  EXPECT_NE(why.find("foot 'foot''s lowest contact points (3 within 1 mm of the lowest) span 0.2 x 0 m"),
            std::string::npos)
      << why;
  // Two points are no sole either.
  why.clear();
  EXPECT_FALSE(
      FindSole("foot", {Sphere("foot", -0.1, -0.05, 0), Sphere("foot", 0.1, 0.05, 0)}, &why).has_value());
  EXPECT_NE(why.find("(2 within"), std::string::npos) << why;
  // A box rotated in the link frame.
  why.clear();
  CollisionShape tilted = Box("foot", {0.2, 0.1, 0.02}, {0, 0, -0.05});
  tilted.origin.rotation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
  EXPECT_FALSE(FindSole("foot", {tilted}, &why).has_value());
  EXPECT_NE(why.find("rotated"), std::string::npos) << why;
}

// The rocking of the whole robot on a sole of four corner springs k, w
// apart (a mass m at the CoM height h): ω² = k w² / (m h²) − g / h.
double RockingOmegaSq(double k, double w, double m, double h, double g) {
  return k * w * w / (m * h * h) - g / h;
}

TEST(SoleFromModel, TheSoleSpringKeepsTheTunedRockingForAHeavierTallerRobot) {
  using W = WalkingHumanoid;
  const W::SoleSpring tuned = W::SoleSpringFor(W::kSoleTunedMass, W::kSoleTunedComHeight, 9.81);
  EXPECT_EQ(tuned.stiffness, W::kSoleStiffness) << "the tuned model keeps its values exactly";
  EXPECT_EQ(tuned.damping, W::kSoleDamping);
  // Atlas: 175.1 kg, CoM 1.169 m up in the stance.
  const W::SoleSpring atlas = W::SoleSpringFor(175.1, 1.169, 9.81);
  const double w = W::kSoleTunedWidth;
  const double w0 =
      std::sqrt(RockingOmegaSq(W::kSoleStiffness, w, W::kSoleTunedMass, W::kSoleTunedComHeight, 9.81));
  EXPECT_NEAR(w0, 9.5, 0.05);
  EXPECT_NEAR(std::sqrt(RockingOmegaSq(atlas.stiffness, w, 175.1, 1.169, 9.81)), w0, 0.01 * w0)
      << "the same rocking frequency on a sole of the tuned width";
  // Damping ratio c w² / (2 m h² ω): the same.
  const auto zeta = [&](double c, double m, double h) { return c * w * w / (2 * m * h * h * w0); };
  EXPECT_NEAR(zeta(atlas.damping, 175.1, 1.169),
              zeta(W::kSoleDamping, W::kSoleTunedMass, W::kSoleTunedComHeight), 0.001);
  // Stiffer than mass per contact alone would make it (each corner sinking
  // as deep, 6.7e5 N/m): that sole was measured too soft (docs/ode_sim.md).
  EXPECT_GT(atlas.stiffness, 2 * W::kSoleStiffness * 175.1 / W::kSoleTunedMass);
  // Lighter and lower: softer.
  EXPECT_LT(W::SoleSpringFor(30, 0.5, 9.81).stiffness, W::kSoleStiffness);
}

TEST(SoleFromModel, APointFootedHumanoidGetsItsGaitGeometryFromThePoints) {
  const TempUrdf urdf("sole_test", PointFootedHumanoid(SixPointSoles()));
  const RobotModel model = LoadUrdfFile(urdf.path).model;
  const std::vector<CollisionShape> shapes = LoadCollisionShapes(urdf.path);
  std::string why;
  const auto walker = WalkingHumanoid::Create(model, shapes, OdeDriverOptions{}, 1e-3, &why);
  ASSERT_NE(walker, nullptr) << why;
  const auto boxed = WalkingHumanoid::Create(
      LoadUrdfFile(testing::ProjectModel("simple_humanoid.urdf")).model,
      LoadCollisionShapes(testing::ProjectModel("simple_humanoid.urdf")), OdeDriverOptions{}, 1e-3, &why);
  ASSERT_NE(boxed, nullptr) << why;
  // The same sole as the box's, so the same gait geometry.
  const walking::GaitParams& g = walker->gait();
  const walking::GaitParams& b = boxed->gait();
  EXPECT_DOUBLE_EQ(g.foot_front, b.foot_front);
  EXPECT_DOUBLE_EQ(g.foot_back, b.foot_back);
  EXPECT_DOUBLE_EQ(g.foot_half_width, b.foot_half_width);
  EXPECT_DOUBLE_EQ(g.foot_separation, b.foot_separation);
  EXPECT_NEAR(g.com_height, b.com_height, 1e-9);
  // Its points become the box the sole is (its spring is then the tuned one).
  EXPECT_EQ(walker->sole_spring().stiffness, WalkingHumanoid::kSoleStiffness);
  EXPECT_EQ(walker->sole_spring().damping, WalkingHumanoid::kSoleDamping);
  std::vector<CollisionShape> world_shapes = shapes;
  ode_detail::OdeWorldOptions world;
  walker->Prepare(world, world_shapes);
  EXPECT_TRUE(world.place_on_ground);
  for (const char* foot : {"left_foot", "right_foot"}) {
    int spheres = 0, boxes = 0;
    for (const CollisionShape& c : world_shapes) {
      if (c.link != foot) continue;
      spheres += c.kind == CollisionShape::Kind::kSphere;
      if (c.kind != CollisionShape::Kind::kBox) continue;
      ++boxes;
      const std::optional<Sole> sole = FindSole(foot, {c}, &why);
      ASSERT_TRUE(sole.has_value()) << why;
      EXPECT_NEAR(sole->front, 0.15, 1e-9);
      EXPECT_NEAR(sole->back, 0.09, 1e-9);
      EXPECT_NEAR(sole->left, 0.06, 1e-9);
      EXPECT_NEAR(sole->right, 0.06, 1e-9);
      EXPECT_NEAR(sole->z, -0.07, 1e-9);
    }
    EXPECT_EQ(spheres, 1) << foot << ": the bumper above the sole stays, the sole's points go";
    EXPECT_EQ(boxes, 1) << foot;
  }
}

TEST(SoleFromModel, AHumanoidWhoseFeetHaveNoSoleIsRefusedWithTheReason) {
  // Two points a foot: no sole.
  const TempUrdf urdf("sole_test",
                      PointFootedHumanoid(ContactPoint(-0.09, 0, -0.07) + ContactPoint(0.15, 0, -0.07)));
  std::string why;
  EXPECT_EQ(WalkingHumanoid::Create(LoadUrdfFile(urdf.path).model, LoadCollisionShapes(urdf.path),
                                    OdeDriverOptions{}, 1e-3, &why),
            nullptr);
  EXPECT_NE(why.find("foot 'left_foot''s lowest contact points (2 within 1 mm of the lowest)"),
            std::string::npos)
      << why;
}

}  // namespace
}  // namespace robotalk

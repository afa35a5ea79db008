// Foot damping (drivers/ode_sim/walking/foot_damping.h), tested without ODE:
// the ZMP's split between the feet, the ankle offsets' directions, bounds and
// landing phase, and a sole on a rubber pad (its CoP moves with the ankle
// angle the servo holds, as the ODE walker's sole springs make it) whose
// CoP a body pushes toward the toe: the damping brings it back to the
// desired CoP, the stiff ankle (no damping) leaves it at the edge.
#include "walking/foot_damping.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace robotalk::walking {
namespace {

constexpr double kWeight = 515, kTick = 0.001;
const SoleRect kSole{0.15, 0.09, 0.06};  // the simple humanoid's sole around its ankle

TEST(FootDamping, OneFootOnTheGroundTakesTheWholeZmpClampedIntoItsSole) {
  const std::array<Pose2, 2> feet{Pose2{1, 0.1, 0.5}, Pose2{1, -0.1, 0}};
  // 2 cm ahead and 1 cm left of the left ankle, in its (turned) frame.
  const Eigen::Vector2d zmp = feet[0].Apply(0.02, 0.01);
  FootTargets t = DistributeZmp(zmp, feet, {true, false}, kSole, 0.01);
  EXPECT_DOUBLE_EQ(t.share[0], 1);
  EXPECT_DOUBLE_EQ(t.share[1], 0);
  EXPECT_NEAR(t.cop[0].x(), 0.02, 1e-12);
  EXPECT_NEAR(t.cop[0].y(), 0.01, 1e-12);
  // Far outside: clamped 1 cm inside the sole's front and left edges.
  t = DistributeZmp(feet[0].Apply(0.5, 0.5), feet, {true, false}, kSole, 0.01);
  EXPECT_NEAR(t.cop[0].x(), 0.14, 1e-12);
  EXPECT_NEAR(t.cop[0].y(), 0.05, 1e-12);
  // The right foot alone.
  t = DistributeZmp(feet[1].Apply(-0.03, -0.02), feet, {false, true}, kSole, 0.01);
  EXPECT_DOUBLE_EQ(t.share[1], 1);
  EXPECT_NEAR(t.cop[1].x(), -0.03, 1e-12);
  EXPECT_NEAR(t.cop[1].y(), -0.02, 1e-12);
}

TEST(FootDamping, InDoubleSupportTheZmpIsSharedByWhereItLiesBetweenTheSoles) {
  const std::array<Pose2, 2> feet{Pose2{0, 0.09, 0}, Pose2{0, -0.09, 0}};
  const double cx = 0.5 * (kSole.front - kSole.back);  // the soles' centres are 3 cm ahead of the ankles
  // A quarter of the way from the left sole's centre to the right one's, 1 cm ahead of that line.
  const FootTargets t = DistributeZmp({cx + 0.01, 0.09 - 0.045}, feet, {true, true}, kSole, 0.01);
  EXPECT_NEAR(t.share[0], 0.75, 1e-12);
  EXPECT_NEAR(t.share[1], 0.25, 1e-12);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(t.cop[static_cast<size_t>(i)].x(), cx + 0.01, 1e-12) << i;
    EXPECT_NEAR(t.cop[static_cast<size_t>(i)].y(), 0, 1e-12) << i;
  }
  // Beyond the left sole: all of it on the left foot.
  EXPECT_NEAR(DistributeZmp({cx, 0.3}, feet, {true, true}, kSole, 0.01).share[0], 1, 1e-12);
  // No foot down: no share, the soles' centres.
  const FootTargets none = DistributeZmp({0, 0}, feet, {false, false}, kSole, 0.01);
  EXPECT_EQ(none.share[0] + none.share[1], 0);
  EXPECT_NEAR(none.cop[0].x(), cx, 1e-12);
}

TEST(FootDamping, TheAnkleGivesWayTowardWhereTheCopShouldBe) {
  FootDamping d(kWeight, kTick);
  // CoP 3 cm ahead of the desired one on a loaded foot: the toe is lifted
  // (pitch < 0); 2 cm to the left: the left edge is lifted (roll > 0).
  const Eigen::Vector2d a = d.Update(0, {0, 0}, {kWeight, {0.03, 0.02}});
  EXPECT_LT(a.y(), 0);
  EXPECT_GT(a.x(), 0);
  // Behind and to the right: the other way.
  const Eigen::Vector2d b = d.Update(1, {0, 0}, {kWeight, {-0.03, -0.02}});
  EXPECT_GT(b.y(), 0);
  EXPECT_LT(b.x(), 0);
  // At the desired CoP the offset only leaks back toward flat.
  FootDamping e(kWeight, kTick);
  for (int i = 0; i < 100; ++i) e.Update(0, {0, 0}, {kWeight, {0.03, 0}});
  const double held = e.offset(0).y();
  for (int i = 0; i < 100; ++i) e.Update(0, {0.01, 0}, {kWeight, {0.01, 0}});
  EXPECT_LT(std::abs(e.offset(0).y()), std::abs(held));
  EXPECT_GT(std::abs(e.offset(0).y()), 0.5 * std::abs(held));  // leak 1 s: 0.1 s leaves most
}

TEST(FootDamping, OffsetsAndTheirRatesAreBoundedAndAFootInTheAirTurnsFlat) {
  const FootDampingGains g;
  FootDamping d(kWeight, kTick, g);
  const Eigen::Vector2d first = d.Update(0, {0, 0}, {10 * kWeight, {1, 1}});
  EXPECT_LE(first.cwiseAbs().maxCoeff(), g.max_rate * kTick + 1e-15);
  for (int i = 0; i < 2000; ++i) d.Update(0, {0, 0}, {10 * kWeight, {1, 1}});
  EXPECT_NEAR(d.offset(0).cwiseAbs().maxCoeff(), g.max_angle, 1e-12);
  for (int i = 0; i < 500; ++i) d.Update(0, {0, 0}, {0, {0, 0}});  // in the air for 0.5 s
  EXPECT_LT(d.offset(0).cwiseAbs().maxCoeff(), 1e-3);
  // An unloaded foot (below contact_force) is not driven by its CoP.
  FootDamping u(kWeight, kTick, g);
  u.Update(1, {0, 0}, {0.5 * g.contact_force, {0.05, 0.05}});
  EXPECT_EQ(u.offset(1).norm(), 0);
  // Non-finite measurements count as no contact.
  u.Update(1, {0, 0}, {std::numeric_limits<double>::quiet_NaN(), {0, 0}});
  EXPECT_TRUE(u.offset(1).allFinite());
}

TEST(FootDamping, SwitchedOffTheOffsetReturnsToFlatOverTheLeakAndTheFootIsNotLanding) {
  // push_balance=damping: the loop runs only while a push's stop holds;
  // then Relax brings the ankle back to the IK's angle, smoothly.
  const FootDampingGains g;
  FootDamping d(kWeight, kTick, g);
  for (int i = 0; i < 2000; ++i) d.Update(0, {0, 0}, {kWeight, {0.05, -0.03}});
  const Eigen::Vector2d held = d.offset(0);
  ASSERT_GT(held.cwiseAbs().minCoeff(), 0.01);
  double worst_step = 0;
  Eigen::Vector2d last = held;
  for (int i = 0; i < static_cast<int>(g.leak / kTick); ++i) {
    const Eigen::Vector2d now = d.Relax(0);
    worst_step = std::max(worst_step, (now - last).cwiseAbs().maxCoeff());
    last = now;
  }
  // exp(-1) after one leak time, each component toward 0 without crossing it.
  for (int k = 0; k < 2; ++k) EXPECT_NEAR(last[k] / held[k], std::exp(-1.0), 0.01) << k;
  EXPECT_LE(worst_step, g.max_rate * kTick + 1e-15);
  for (int i = 0; i < 5000; ++i) d.Relax(0);
  EXPECT_LT(d.offset(0).norm(), 1e-3);
  EXPECT_FALSE(d.landing(0));
  // Back on with the foot loaded on the ground: not a landing (no extra compliance).
  d.Update(0, {0, 0}, {0.1 * kWeight, {0, 0}});
  EXPECT_FALSE(d.landing(0));
  EXPECT_THROW(d.Relax(2), std::invalid_argument);
}

// Foot force difference control on two feet standing on springs (k each,
// a rigid body on them: the forces change by k times each sole's move):
// the overloaded foot rises and the other presses down until the forces'
// difference is the desired one; out of double support and switched off
// it returns to 0.
TEST(ForceDifference, TheFeetsHeightsBringTheForcesDifferenceToTheDesiredOne) {
  constexpr double kStiff = 8e5, kRate = 10;
  const ForceDifferenceGains g = ForceDifferenceFor(kStiff, kRate);
  EXPECT_DOUBLE_EQ(g.admittance, kRate / kStiff);
  ForceDifference f(kTick, g);
  // Rolled onto the left foot: 400 N left, 115 N right, wanted half each.
  const double left0 = 400, right0 = kWeight - left0;
  std::array<double, 2> force{left0, right0};
  for (int i = 0; i < 1000; ++i) {
    const double h = f.Update({0.5, 0.5}, force, true);
    force = {left0 - 0.5 * kStiff * h, right0 + 0.5 * kStiff * h};  // the left sole raised by h/2
  }
  EXPECT_GT(f.height(), 0) << "the overloaded left foot rises";
  EXPECT_LE(f.height(), g.max_height);
  // The leak leaves a small steady error: |e| = h / (A T_leak), under 20 % of the first.
  EXPECT_LT(std::abs(force[0] - force[1]), 0.2 * (left0 - right0));
  // The other way round: the right foot overloaded, the left lowered (h < 0).
  ForceDifference r(kTick, g);
  for (int i = 0; i < 100; ++i) r.Update({0.5, 0.5}, {100, 415}, true);
  EXPECT_LT(r.height(), 0);
  // Rates and bounds (a gain high enough to reach them).
  ForceDifferenceGains high = g;
  high.admittance = 1e-3;
  ForceDifference b(kTick, high);
  EXPECT_LE(std::abs(b.Update({0.5, 0.5}, {kWeight, 0}, true)), g.max_rate * kTick + 1e-15);
  for (int i = 0; i < 2000; ++i) b.Update({0.5, 0.5}, {kWeight, 0}, true);
  EXPECT_NEAR(b.height(), g.max_height, 1e-12);
  // Single support: back to 0 over air_return.
  for (int i = 0; i < 1000; ++i) b.Update({1, 0}, {kWeight, 0}, false);
  EXPECT_LT(std::abs(b.height()), 1e-4);
  // Switched off: back to 0 over the leak.
  for (int i = 0; i < 2000; ++i) b.Update({0.5, 0.5}, {kWeight, 0}, true);
  for (int i = 0; i < static_cast<int>(g.leak / kTick); ++i) b.Relax();
  EXPECT_NEAR(b.height() / g.max_height, std::exp(-1.0), 0.01);
  // Non-finite measurements count as out of double support; bad gains are refused.
  EXPECT_TRUE(std::isfinite(b.Update({0.5, 0.5}, {std::numeric_limits<double>::quiet_NaN(), 0}, true)));
  EXPECT_THROW(ForceDifference(0), std::invalid_argument);
  EXPECT_THROW(ForceDifference(kTick, ForceDifferenceGains{.max_height = 0}), std::invalid_argument);
  EXPECT_THROW(ForceDifferenceFor(-1, kRate), std::invalid_argument);
  EXPECT_THROW(ForceDifferenceFor(kStiff, 0), std::invalid_argument);
}

TEST(FootDamping, ALandingFootIsCompliantUntilLoaded) {
  const FootDampingGains g;
  FootDamping d(kWeight, kTick, g);
  d.Update(0, {0, 0}, {0, {0, 0}});  // lifted
  EXPECT_FALSE(d.landing(0));
  // Touching on its heel's outer corner with 50 N: landing, turned as fast
  // as a fully loaded foot would be (not 50/515 of it).
  const Eigen::Vector2d light = d.Update(0, {0, 0}, {50, {-0.05, -0.04}});
  EXPECT_TRUE(d.landing(0));
  FootDamping loaded(kWeight, kTick, g);
  const Eigen::Vector2d full = loaded.Update(0, {0, 0}, {kWeight, {-0.05, -0.04}});
  EXPECT_NEAR(light.x(), full.x(), 1e-12);
  EXPECT_NEAR(light.y(), full.y(), 1e-12);
  EXPECT_GT(light.y(), 0);  // the toe goes down onto the ground
  EXPECT_LT(light.x(), 0);  // and the inner edge
  // Loaded past `loaded` of the weight: the landing ends, the admittance is the torque's again.
  d.Update(0, {0, 0}, {g.loaded * kWeight + 1, {0, 0}});
  EXPECT_FALSE(d.landing(0));
  // A foot standing from the start is not landing.
  FootDamping s(kWeight, kTick, g);
  s.Update(1, {0, 0}, {50, {0, 0}});
  EXPECT_FALSE(s.landing(1));
}

// A sole on a rubber pad under a stiff ankle: the body presses the CoP
// `lean` ahead (m; its ZMP); the ankle turned by pitch p shifts it by
// (rolling stiffness / load) p (toe down: forward). The ODE walker's sole
// springs: 4 corners of 2e5 N/m over a 0.24 m long sole: ~8000 N·m/rad.
double SteadyCop(bool damped, double lean) {
  constexpr double kStiffness = 8000;  // N·m/rad
  FootDamping d(kWeight, kTick);
  double cop = lean;
  for (int i = 0; i < 3000; ++i) {
    const double pitch = damped ? d.Update(0, {0.01, 0}, {kWeight, {cop, 0}}).y() : 0.0;
    cop = std::clamp(lean + kStiffness / kWeight * pitch, -kSole.back, kSole.front);
  }
  return cop;
}

TEST(FootDamping, ASoleLeveredOntoItsToeIsBroughtBackToItsDesiredCop) {
  // Stiff ankle: the CoP stays where the body put it, at the toe.
  EXPECT_NEAR(SteadyCop(false, 0.15), 0.15, 1e-12);
  // Damped: within 2 cm of the desired 1 cm (the leak leaves 1 / (1 +
  // leak A K) of the error: 14 cm -> 1.6 cm).
  EXPECT_NEAR(SteadyCop(true, 0.15), 0.01, 0.02);
  EXPECT_NEAR(SteadyCop(true, -0.06), 0.01, 0.02);
}

TEST(FootDamping, TheAdmittanceKeepsTheTunedSolesLoopRateOnOtherSoles) {
  EXPECT_EQ(AdmittanceFor(kTunedSoleStiffness, kTunedSoleLength), kTunedAdmittance);
  EXPECT_EQ(AdmittanceFor(kTunedSoleStiffness * 1.0005, kTunedSoleLength), kTunedAdmittance);
  // Admittance x rolling stiffness (stiffness x length^2) stays the tuned one's.
  const double tuned = kTunedAdmittance * kTunedSoleStiffness * kTunedSoleLength * kTunedSoleLength;
  EXPECT_NEAR(AdmittanceFor(8 * kTunedSoleStiffness, 0.25) * 8 * kTunedSoleStiffness * 0.25 * 0.25, tuned,
              1e-12);
  EXPECT_LT(AdmittanceFor(8 * kTunedSoleStiffness, kTunedSoleLength), kTunedAdmittance);
  EXPECT_THROW(AdmittanceFor(0, 0.2), std::invalid_argument);
  EXPECT_THROW(AdmittanceFor(1e5, -1), std::invalid_argument);
}

TEST(FootDamping, BadParametersAndFeetAreRefusedByName) {
  EXPECT_THROW(FootDamping(0, kTick), std::invalid_argument);
  EXPECT_THROW(FootDamping(kWeight, -1), std::invalid_argument);
  EXPECT_THROW(FootDamping(kWeight, kTick, {.admittance = 0}), std::invalid_argument);
  EXPECT_THROW(FootDamping(kWeight, kTick, {.loaded = 1.5}), std::invalid_argument);
  FootDamping d(kWeight, kTick);
  try {
    d.Update(2, {0, 0}, {});
    FAIL() << "foot 2 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("foot 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace robotalk::walking

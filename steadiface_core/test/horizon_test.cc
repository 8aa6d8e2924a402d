// The level horizon: gravity from the accelerometer against the gyro
// (GravityEstimator), the roll it defines (HorizonRoll) and the horizon
// term E_h, against closed forms.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "steadiface_core/gyro/orientation_timeline.h"
#include "steadiface_core/stabilizer/horizon_cost.h"
#include "steadiface_core/view/gravity.h"

namespace steadiface {
namespace {

Time At(double s) { return Time(FromSeconds(s)); }

Eigen::Quaterniond Roll(double rad) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(rad, Eigen::Vector3d::UnitZ()));
}

TEST(HorizonRollTest, IsTheAngleFromTheImagesUpToGravitysUp) {
  EXPECT_NEAR(HorizonRoll(Eigen::Vector3d(0, -1, 0)), 0.0, 1e-15);
  // A camera rolled by a about its optical axis (camera -> world Roll(a))
  // sees the world's up turned by -a.
  for (double a : {-0.3, 0.05, 0.17}) {
    const Eigen::Vector3d up_cam =
        Roll(a).conjugate() * Eigen::Vector3d(0, -1, 0);
    EXPECT_NEAR(HorizonRoll(up_cam), -a, 1e-12) << a;
  }
  // Tilting forwards (pitch) leaves the roll 0.
  const Eigen::Quaterniond pitch(
      Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()));
  EXPECT_NEAR(HorizonRoll(pitch * Eigen::Vector3d(0, -1, 0)), 0.0, 1e-12);
}

// A camera held still, rolled by `roll` and shaken by `accel_noise` (white,
// [m/s^2]) on top of gravity; the gyro reads 0.
struct StillCamera {
  OrientationTimeline timeline{OrientationTimelineOptions()};
  GravityEstimator gravity;
  explicit StillCamera(const HorizonOptions& o) : gravity(o) {}
  // From t0 [s] for `seconds`, 200 Hz.
  void Run(double roll, double t0, double seconds, double accel_noise,
           double extra_g = 0.0) {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> n01(0.0, 1.0);
    // At rest the accelerometer reads 1 g up, in the camera frame.
    const Eigen::Vector3d up_cam =
        Roll(roll).conjugate() * Eigen::Vector3d(0, -1, 0);
    for (int i = 0; i <= seconds * 200; ++i) {
      const Time t = At(t0 + i / 200.0);
      ASSERT_EQ(timeline.AddSample({t, Eigen::Vector3d::Zero()}),
                SampleResult::kAccepted);
      const Eigen::Vector3d a =
          (1.0 + extra_g) * kStandardGravity * up_cam +
          accel_noise * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
      gravity.Add(t, a, timeline);
    }
  }
};

TEST(GravityEstimatorTest, FindsTheRollOfAStillCameraAfterItsWarmUp) {
  HorizonOptions o;
  StillCamera cam(o);
  const double roll = 0.12;
  cam.Run(roll, 0.0, 0.2, 0.05);
  EXPECT_FALSE(cam.gravity.valid()) << "0.2 s < the 0.3 s warm-up";
  cam.Run(roll, 0.205, 2.0, 0.05);
  ASSERT_TRUE(cam.gravity.valid());
  // The gyro's world frame is the camera's first orientation: gravity's up
  // there is the rolled camera's up, roll -0.12 rad, to 1 mrad (0.05 m/s^2
  // of noise per reading is 5 mrad; 440 of them average to 0.25).
  EXPECT_NEAR(HorizonRoll(cam.gravity.up_world()), -roll, 1e-3);
  EXPECT_NEAR(cam.gravity.up_world().norm(), 1.0, 1e-12);
  EXPECT_EQ(cam.gravity.rejected(), 0u);
}

TEST(GravityEstimatorTest, LeavesOutReadingsFarFromOneG) {
  HorizonOptions o;
  StillCamera cam(o);
  cam.Run(0.0, 0.0, 1.0, 0.0, /*extra_g=*/0.5);  // accelerating: 1.5 g
  EXPECT_FALSE(cam.gravity.valid());
  EXPECT_EQ(cam.gravity.accepted(), 0u);
  EXPECT_EQ(cam.gravity.rejected(), 201u);
  // Readings before the gyro covers them are left out too.
  const Eigen::Vector3d a(0, -kStandardGravity, 0);
  EXPECT_FALSE(cam.gravity.Add(At(5.0), a, cam.timeline));
  EXPECT_FALSE(
      cam.gravity.Add(At(0.5), Eigen::Vector3d(NAN, 0, 0), cam.timeline));
  cam.gravity.Reset();
  EXPECT_FALSE(cam.gravity.valid());
}

TEST(GravityEstimatorTest, TheGyroCarriesTheOrientationBetweenReadings) {
  // The camera turns about its optical axis at 0.5 rad/s; the readings turn
  // with it in the camera, but gravity in the gyro's world frame stays put.
  HorizonOptions o;
  GravityEstimator gravity(o);
  OrientationTimeline tl{OrientationTimelineOptions()};
  for (int i = 0; i <= 400; ++i) {
    const double t = i / 200.0;
    ASSERT_EQ(tl.AddSample({At(t), Eigen::Vector3d(0, 0, 0.5)}),
              SampleResult::kAccepted);
    const Eigen::Vector3d up_cam =
        Roll(0.5 * t).conjugate() * Eigen::Vector3d(0, -1, 0);
    gravity.Add(At(t), kStandardGravity * up_cam, tl);
  }
  ASSERT_TRUE(gravity.valid());
  EXPECT_NEAR(HorizonRoll(gravity.up_world()), 0.0, 2e-3);
}

TEST(HorizonCostTest, IsTheSineOfTheRollTimesTheScale) {
  const Eigen::Vector3d up_world(0, -1, 0);
  const double scale = 3.0;
  for (double a : {0.0, 0.1, -0.25}) {
    // A virtual camera (world -> camera) rolled by a about its axis.
    const Eigen::Quaterniond R_v = Roll(a);
    const double q[4] = {R_v.x(), R_v.y(), R_v.z(), R_v.w()};
    double r = NAN;
    ASSERT_TRUE(HorizonCost(up_world, scale, 0.0)(q, &r));
    const double roll = HorizonRoll(R_v * up_world);
    EXPECT_NEAR(r, scale * std::sin(roll), 1e-12) << a;
    EXPECT_NEAR(std::abs(r), scale * std::abs(std::sin(a)), 1e-12) << a;
  }
  // Looking straight up: no pull.
  const Eigen::Quaterniond up(
      Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()));
  const double q[4] = {up.x(), up.y(), up.z(), up.w()};
  double r = NAN;
  ASSERT_TRUE(HorizonCost(up_world, scale, 0.0)(q, &r));
  EXPECT_EQ(r, 0.0);
}

// level's tolerance: a roll within phi_0 is left alone, and beyond it the
// residual is the sine's excess, continuous at the edge.
TEST(HorizonCostTest, LeavesARollWithinTheToleranceAlone) {
  const Eigen::Vector3d up_world(0, -1, 0);
  const double scale = 2.0, phi0 = 1.0 * M_PI / 180.0;
  for (double a : {-0.5, 0.0, 0.3, 0.9, 1.0, 1.5, -2.0, 10.0}) {
    const Eigen::Quaterniond R_v = Roll(a * M_PI / 180.0);
    const double q[4] = {R_v.x(), R_v.y(), R_v.z(), R_v.w()};
    double r = NAN;
    ASSERT_TRUE(HorizonCost(up_world, scale, std::sin(phi0))(q, &r));
    const double s = std::sin(HorizonRoll(R_v * up_world));
    const double excess = std::max(0.0, std::abs(s) - std::sin(phi0));
    EXPECT_NEAR(std::abs(r), scale * excess, 1e-12) << a;
    if (excess > 0.0) EXPECT_EQ(r > 0.0, s > 0.0) << "pulls towards level: " << a;
  }
  // 1.5 deg with a 1 deg tolerance pulls as 0.5 deg would without one, to
  // first order.
  const Eigen::Quaterniond R_v = Roll(1.5 * M_PI / 180.0);
  const double q[4] = {R_v.x(), R_v.y(), R_v.z(), R_v.w()};
  double r = NAN;
  ASSERT_TRUE(HorizonCost(up_world, scale, std::sin(phi0))(q, &r));
  EXPECT_NEAR(std::abs(r), scale * 0.5 * M_PI / 180.0, 1e-5);
}

TEST(HorizonOptionsTest, AreChecked) {
  EXPECT_TRUE(ValidateHorizonOptions(HorizonOptions()).ok());
  HorizonOptions o;
  o.gravity_tolerance = 0.0;
  EXPECT_FALSE(ValidateHorizonOptions(o).ok());
  o = HorizonOptions();
  o.lowpass_hz = NAN;
  EXPECT_FALSE(ValidateHorizonOptions(o).ok());
  o = HorizonOptions();
  o.level_tolerance_deg = -0.5;
  EXPECT_FALSE(ValidateHorizonOptions(o).ok());
  HorizonMode m;
  EXPECT_TRUE(ParseHorizonMode("lock", &m).ok());
  EXPECT_EQ(m, HorizonMode::kLock);
  EXPECT_FALSE(ParseHorizonMode("tilt", &m).ok());
  EXPECT_STREQ(HorizonModeName(HorizonMode::kLevel), "level");
}

}  // namespace
}  // namespace steadiface

#include "steadiface_core/stabilizer/pose_invariant_centre.h"

#include <cmath>

#include <gtest/gtest.h>

namespace steadiface {
namespace {

FaceObservation Turned(double yaw, double scale) {
  FaceObservation f;
  f.valid = true;
  f.has_pose = true;
  f.yaw = yaw;
  f.scale = scale;
  f.landmarks = {Eigen::Vector2d(0.1, 0.2), Eigen::Vector2d(0.3, -0.1)};
  f.centre = Eigen::Vector2d(0.2, 0.05);
  return f;
}

TEST(PoseInvariantCentreTest, MovesTheLandmarksBackByThePivotDepthTimesSinYaw) {
  // A face turned by 0.5 rad whose scale is 0.05: the centre swings by
  // -d sin(yaw) sideways; it is moved back by +1.5 * 0.05 * sin(0.5).
  PoseInvariantCentre c(1.5, 0.1);
  const FaceObservation out = c.Apply(Turned(0.5, 0.05), 0.0);
  const double shift = 1.5 * 0.05 * std::sin(0.5);
  EXPECT_NEAR(out.centre.x(), 0.2 + shift, 1e-12);
  EXPECT_NEAR(out.centre.y(), 0.05, 1e-12);
  EXPECT_NEAR(out.landmarks[0].x(), 0.1 + shift, 1e-12);
  EXPECT_NEAR(out.landmarks[1].y(), -0.1, 1e-12);
  EXPECT_NEAR(c.last_shift(), shift, 1e-12);
}

TEST(PoseInvariantCentreTest, TheYawIsLowPassedAndForgottenWithTheFace) {
  PoseInvariantCentre c(1.0, 0.1);
  c.Apply(Turned(0.0, 1.0), 0.0);
  // One frame (1/30 s) after a step to 0.3 rad: exp(-1/3) of the old yaw.
  c.Apply(Turned(0.3, 1.0), 1.0 / 30.0);
  const double a = std::exp(-1.0 / 3.0);
  EXPECT_NEAR(c.last_shift(), std::sin((1.0 - a) * 0.3), 1e-12);
  // After a reset (the face was lost) the yaw starts again from the face's.
  c.Reset();
  c.Apply(Turned(0.3, 1.0), 1.0 / 30.0);
  EXPECT_NEAR(c.last_shift(), std::sin(0.3), 1e-12);
}

TEST(PoseInvariantCentreTest, WithoutAPoseOrSwitchedOffTheFaceIsUnchanged) {
  FaceObservation no_pose = Turned(0.5, 0.05);
  no_pose.has_pose = false;
  PoseInvariantCentre on(1.5, 0.1), off(0.0, 0.1);
  EXPECT_EQ(on.Apply(no_pose, 0.03).centre, no_pose.centre);
  EXPECT_EQ(off.Apply(Turned(0.5, 0.05), 0.03).centre,
            Turned(0.5, 0.05).centre);
  FaceObservation nan_yaw = Turned(NAN, 0.05);
  EXPECT_EQ(on.Apply(nan_yaw, 0.03).centre, nan_yaw.centre);
}

}  // namespace
}  // namespace steadiface

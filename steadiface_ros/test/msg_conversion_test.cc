#include "steadiface_ros/msg_conversion.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "steadiface_ros/time_conversion.h"

namespace steadiface_ros {
namespace {

sensor_msgs::CameraInfo MakeInfo() {
  sensor_msgs::CameraInfo info;
  info.width = 1280;
  info.height = 720;
  info.K = {1000.0, 0.0, 640.5, 0.0, 1005.0, 360.25, 0.0, 0.0, 1.0};
  info.distortion_model = "plumb_bob";
  info.D = {0.0, 0.0, 0.0, 0.0, 0.0};
  return info;
}

TEST(MsgConversionTest, CameraInfoToIntrinsics) {
  steadiface::CameraIntrinsics k;
  const steadiface::Status s = ToCameraIntrinsics(MakeInfo(), &k);
  ASSERT_TRUE(s.ok()) << s.message();
  EXPECT_EQ(k.width, 1280);
  EXPECT_EQ(k.height, 720);
  EXPECT_DOUBLE_EQ(k.fx, 1000.0);
  EXPECT_DOUBLE_EQ(k.fy, 1005.0);
  EXPECT_DOUBLE_EQ(k.cx, 640.5);
  EXPECT_DOUBLE_EQ(k.cy, 360.25);
  // All-zero D means no distortion.
  EXPECT_EQ(k.distortion, steadiface::DistortionModel::kNone);
  EXPECT_FALSE(k.HasDistortion());
}

TEST(MsgConversionTest, AFollowedFaceIsPublishedAsFollowedNotValid) {
  steadiface::FaceInfo f;
  f.state = steadiface::TrackingState::kLost;
  f.failure = steadiface::FaceFailure::kImplausibleShape;
  f.followed = true;
  f.landmarks_px = {Eigen::Vector2d(10.0, 20.0), Eigen::Vector2d(30.0, 40.0)};
  f.centre_px = Eigen::Vector2d(20.0, 30.0);
  f.has_pose = true;
  f.yaw = 1.1;
  std_msgs::Header h;
  h.frame_id = "camera";
  const steadiface::FaceLandmarks m = ToMsg(f, h);
  EXPECT_FALSE(m.valid);
  EXPECT_TRUE(m.followed);
  EXPECT_EQ(m.state, steadiface::FaceLandmarks::LOST);
  EXPECT_EQ(m.failure, "implausible_shape");
  ASSERT_EQ(m.points.size(), 2u);
  EXPECT_DOUBLE_EQ(m.points[1].y, 40.0);
  EXPECT_DOUBLE_EQ(m.centre.x, 20.0);
  EXPECT_FLOAT_EQ(m.yaw, 1.1f);
  EXPECT_TRUE(f.located());
  f.followed = false;
  EXPECT_FALSE(ToMsg(f, h).followed);
  EXPECT_FALSE(f.located());
}

TEST(MsgConversionTest, TheStateNamesTheRotationSourceAndPublishesNothingNonFinite) {
  std_msgs::Header h;
  h.frame_id = "camera";
  steadiface::PipelineFrame pf;
  pf.rotation_from_video = true;
  pf.visual.valid = true;
  pf.visual.tracked = 57;
  pf.visual.inliers = 41;
  pf.visual.residual_px = 0.31;
  pf.visual.turn_error_px = std::numeric_limits<double>::quiet_NaN();
  pf.composite.active = true;
  pf.composite.report.matte_mean = std::numeric_limits<double>::infinity();
  pf.composite.report.plate_share = 0.75;
  pf.composite.report.plate_restarts = -3;
  steadiface::StabilizerState m = ToMsg(pf, h, false);
  EXPECT_EQ(m.rotation_source, "visual");
  EXPECT_TRUE(m.visual_valid);
  EXPECT_EQ(m.visual_tracked, 57u);
  EXPECT_EQ(m.visual_inliers, 41u);
  EXPECT_DOUBLE_EQ(m.visual_residual_px, 0.31);
  EXPECT_EQ(m.visual_turn_error_px, 0.0);  // NaN is never published
  EXPECT_EQ(m.warp_mode, "composite");
  EXPECT_EQ(m.matte_mean, 0.0);  // nor infinity
  EXPECT_DOUBLE_EQ(m.plate_share, 0.75);
  EXPECT_EQ(m.plate_restarts, 0u);  // a negative count is clamped
  // With the IMU, the visual fields stay empty whatever the estimator left.
  pf.rotation_from_video = false;
  m = ToMsg(pf, h, false);
  EXPECT_EQ(m.rotation_source, "imu");
  EXPECT_FALSE(m.visual_valid);
  EXPECT_EQ(m.visual_tracked, 0u);
  EXPECT_EQ(m.visual_residual_px, 0.0);
}

TEST(MsgConversionTest, DistortionModels) {
  steadiface::CameraIntrinsics k;
  sensor_msgs::CameraInfo info = MakeInfo();
  info.D = {-0.2, 0.05, 0.001, -0.002, 0.0};
  ASSERT_TRUE(ToCameraIntrinsics(info, &k).ok());
  EXPECT_EQ(k.distortion, steadiface::DistortionModel::kPlumbBob);
  EXPECT_EQ(k.distortion_coeffs.size(), 5u);
  EXPECT_TRUE(k.HasDistortion());
  info.distortion_model = "equidistant";
  info.D = {0.1, -0.01, 0.002, 0.0};
  ASSERT_TRUE(ToCameraIntrinsics(info, &k).ok());
  EXPECT_EQ(k.distortion, steadiface::DistortionModel::kEquidistant);
  info.distortion_model = "kannala_brandt_9";
  const steadiface::Status s = ToCameraIntrinsics(info, &k);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("kannala_brandt_9"), std::string::npos);
}

TEST(MsgConversionTest, BinningAndRoiAreApplied) {
  sensor_msgs::CameraInfo info = MakeInfo();
  info.binning_x = 2;
  info.binning_y = 2;
  steadiface::CameraIntrinsics k;
  ASSERT_TRUE(ToCameraIntrinsics(info, &k).ok());
  EXPECT_EQ(k.width, 640);
  EXPECT_EQ(k.height, 360);
  EXPECT_DOUBLE_EQ(k.fx, 500.0);
  EXPECT_DOUBLE_EQ(k.cx, 320.25);
  info = MakeInfo();
  info.roi.x_offset = 100;
  info.roi.y_offset = 50;
  info.roi.width = 640;
  info.roi.height = 480;
  ASSERT_TRUE(ToCameraIntrinsics(info, &k).ok());
  EXPECT_EQ(k.width, 640);
  EXPECT_EQ(k.height, 480);
  EXPECT_DOUBLE_EQ(k.cx, 540.5);
  EXPECT_DOUBLE_EQ(k.cy, 310.25);
}

TEST(MsgConversionTest, UncalibratedAndInvalidInfoAreRejected) {
  steadiface::CameraIntrinsics k;
  k.width = 7;
  sensor_msgs::CameraInfo info = MakeInfo();
  info.K.fill(0.0);
  steadiface::Status s = ToCameraIntrinsics(info, &k);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("uncalibrated"), std::string::npos);
  EXPECT_EQ(k.width, 7);  // untouched on error
  info = MakeInfo();
  info.width = 0;
  EXPECT_FALSE(ToCameraIntrinsics(info, &k).ok());
  info = MakeInfo();
  info.K[4] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(ToCameraIntrinsics(info, &k).ok());
}

TEST(MsgConversionTest, ImuToGyroSample) {
  sensor_msgs::Imu imu;
  imu.header.stamp = ros::Time(1700000000, 5);
  imu.angular_velocity.x = 0.1;
  imu.angular_velocity.y = -0.2;
  imu.angular_velocity.z = 0.3;
  const steadiface::GyroSample s = ToGyroSample(imu);
  EXPECT_EQ(s.stamp, ToCoreTime(imu.header.stamp));
  EXPECT_EQ(s.angular_velocity, Eigen::Vector3d(0.1, -0.2, 0.3));
  // Non-finite values pass through for the timeline to count.
  imu.angular_velocity.y = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(ToGyroSample(imu).angular_velocity.allFinite());
}

TEST(MsgConversionTest, QuaternionRoundTripAndRejection) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  Eigen::Quaterniond back;
  ASSERT_TRUE(ToEigen(ToMsg(q), &back));
  EXPECT_TRUE(back.isApprox(q, 1e-15));
  geometry_msgs::Quaternion zero;
  zero.w = 0.0;
  EXPECT_FALSE(ToEigen(zero, &back));
  geometry_msgs::Quaternion nan = ToMsg(q);
  nan.x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(ToEigen(nan, &back));
  const geometry_msgs::Transform t = ToTransformMsg(q);
  EXPECT_EQ(t.translation.x, 0.0);
  EXPECT_DOUBLE_EQ(t.rotation.w, q.w());
}

}  // namespace
}  // namespace steadiface_ros

namespace steadiface_ros {
namespace {

TEST(MsgConversionTest, ImuToAccelSample) {
  sensor_msgs::Imu imu;
  imu.header.stamp = ros::Time(12, 500000000);
  imu.linear_acceleration.x = 0.1;
  imu.linear_acceleration.y = -9.8;
  imu.linear_acceleration.z = 0.3;
  steadiface::AccelSample a;
  ASSERT_TRUE(ToAccelSample(imu, &a));
  EXPECT_DOUBLE_EQ(steadiface::ToSeconds(a.stamp), 12.5);
  EXPECT_EQ(a.linear_acceleration, Eigen::Vector3d(0.1, -9.8, 0.3));
  // "Not provided", by the message's convention or by zeros.
  imu.linear_acceleration_covariance[0] = -1.0;
  EXPECT_FALSE(ToAccelSample(imu, &a));
  imu.linear_acceleration_covariance[0] = 0.0;
  imu.linear_acceleration.x = imu.linear_acceleration.y = imu.linear_acceleration.z = 0.0;
  EXPECT_FALSE(ToAccelSample(imu, &a));
}

}  // namespace
}  // namespace steadiface_ros

// GyroVideoCheck against simulator ground truth: the simulated gyro is
// re-expressed in a permuted IMU frame, or shifted by a clock offset, and
// the check must say so (and name the right mounting / offset) within a few
// seconds; with the right configuration it must stay quiet.
#include "steadiface_core/check/gyro_video_check.h"

#include <iostream>
#include <memory>

#include <gtest/gtest.h>

#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace {

struct CheckRun {
  GyroVideoCheckResult result;
  int frames_to_contradiction = -1;  // first frame the rotation was flagged
};

// Renders `seconds` of the walk preset (no face: background only) and feeds
// the check. The recorded gyro is expressed in an IMU frame mounted as
// `R_imu_cam` and stamped `clock_offset_s` early; the timeline is built with
// `configured_R_cam_imu` and no offset, as a misconfigured node would.
CheckRun Feed(const Eigen::Quaterniond& R_imu_cam, double clock_offset_s,
              const Eigen::Quaterniond& configured_R_cam_imu,
              double seconds = 4.0) {
  sim::SimulatorOptions o;
  EXPECT_TRUE(sim::ApplyPreset("walk", &o).ok());
  o.data_dir = STEADIFACE_TEST_DATA_DIR;
  o.duration_s = seconds;
  o.width = 480;
  o.height = 270;
  o.render_face = false;
  o.imu_clock_offset_s = clock_offset_s;
  std::unique_ptr<sim::Simulator> sim;
  EXPECT_TRUE(sim::Simulator::Create(o, &sim).ok());
  OrientationTimelineOptions to;
  to.R_cam_imu = configured_R_cam_imu;
  OrientationTimeline timeline(to);
  RollingShutterOptions rs;
  rs.readout_time_s = o.readout_s;
  const RowTiming timing(rs, o.height);
  std::unique_ptr<GyroVideoCheck> check;
  EXPECT_TRUE(GyroVideoCheck::Create(sim->intrinsics(), timing,
                                     configured_R_cam_imu,
                                     GyroVideoCheckOptions(), &check)
                  .ok());
  CheckRun run;
  size_t g = 0;
  for (int i = 0; i < sim->num_frames(); ++i) {
    cv::Mat frame;
    sim::SimTruth truth;
    EXPECT_TRUE(sim->Render(i, &frame, &truth).ok()) << i;
    // The gyro up to this frame's last row (as a live node waits for it).
    while (g < sim->imu().size() &&
           sim->imu()[g].stamp <=
               timing.LastRowTime(truth.stamp) + FromSeconds(0.08)) {
      GyroSample s = sim->imu()[g++];
      s.angular_velocity = R_imu_cam * s.angular_velocity;
      timeline.AddSample(s);
    }
    check->Process(frame, truth.stamp, timeline, cv::Rect2d());
    if (run.frames_to_contradiction < 0 &&
        check->result().rotation_contradicts) {
      run.frames_to_contradiction = i;
    }
  }
  run.result = check->result();
  const GyroVideoCheckResult& q = run.result;
  std::cout << "  pairs " << q.pairs << ", motion " << q.motion_px
            << " px, residual configured " << q.residual_configured_px
            << " px, best mounting " << q.residual_best_mounting_px
            << " px, contradicts " << q.rotation_contradicts
            << " (first at frame " << run.frames_to_contradiction
            << "), offset correction " << q.offset_correction_s * 1e3
            << " ms\n";
  return run;
}

double AngleDeg(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return Eigen::AngleAxisd(a * b.conjugate()).angle() * 180.0 / M_PI;
}

TEST(GyroVideoCheckTest,
     TheTwentyFourSignedPermutationsAreDistinctProperRotations) {
  const auto& all = GyroVideoCheck::SignedAxisPermutations();
  ASSERT_EQ(all.size(), 24u);
  for (size_t i = 0; i < all.size(); ++i) {
    EXPECT_NEAR(all[i].toRotationMatrix().determinant(), 1.0, 1e-12);
    for (size_t j = 0; j < i; ++j) EXPECT_GT(AngleDeg(all[i], all[j]), 80.0);
  }
}

TEST(GyroVideoCheckTest, RightConfigurationStaysQuiet) {
  const CheckRun r =
      Feed(Eigen::Quaterniond::Identity(), 0.0, Eigen::Quaterniond::Identity());
  ASSERT_TRUE(r.result.judged)
      << "pairs " << r.result.pairs << ", motion " << r.result.motion_px;
  EXPECT_FALSE(r.result.rotation_contradicts)
      << "configured " << r.result.residual_configured_px << " px, best "
      << r.result.residual_best_mounting_px << " px";
  EXPECT_FALSE(r.result.offset_off) << r.result.offset_correction_s;
  EXPECT_LT(std::abs(r.result.offset_correction_s), 0.003);
  EXPECT_LT(AngleDeg(r.result.best_R_cam_imu, Eigen::Quaterniond::Identity()),
            1.0);
  // The gyro explains the motion: well below the features' own motion.
  EXPECT_LT(r.result.residual_configured_px, 0.3 * r.result.motion_px);
}

TEST(GyroVideoCheckTest,
     APermutedImuLeftAtIdentityIsFlaggedWithTheRightMountingWithinSeconds) {
  // A phone-style mounting: x and y swapped, z flipped.
  const Eigen::Matrix3d M =
      (Eigen::Matrix3d() << 0, 1, 0, 1, 0, 0, 0, 0, -1).finished();
  const Eigen::Quaterniond R_imu_cam(M);
  const CheckRun r = Feed(R_imu_cam, 0.0, Eigen::Quaterniond::Identity());
  ASSERT_TRUE(r.result.judged);
  EXPECT_TRUE(r.result.rotation_contradicts)
      << "configured " << r.result.residual_configured_px << " px, best "
      << r.result.residual_best_mounting_px << " px";
  // The mounting to configure: R_cam_imu = R_imu_cam^-1.
  EXPECT_LT(AngleDeg(r.result.best_R_cam_imu, R_imu_cam.conjugate()), 1.0);
  ASSERT_GE(r.frames_to_contradiction, 0);
  EXPECT_LT(r.frames_to_contradiction, 30 * 3)
      << "flagged only at frame " << r.frames_to_contradiction;
}

TEST(GyroVideoCheckTest,
     APermutedImuWithAnOffsetGetsBothTheMountingAndTheOffset) {
  // Both wrong at once: each mounting is scored at its own best offset.
  const Eigen::Matrix3d M =
      (Eigen::Matrix3d() << 0, 0, 1, 1, 0, 0, 0, 1, 0).finished();
  const Eigen::Quaterniond R_imu_cam(M);
  const CheckRun r = Feed(R_imu_cam, 0.030, Eigen::Quaterniond::Identity());
  ASSERT_TRUE(r.result.judged);
  EXPECT_TRUE(r.result.rotation_contradicts);
  EXPECT_LT(AngleDeg(r.result.best_R_cam_imu, R_imu_cam.conjugate()), 1.0);
  EXPECT_NEAR(r.result.offset_correction_s, 0.030, 0.003);
  EXPECT_FALSE(r.result.offset_off);  // the rotation must be fixed first
}

TEST(GyroVideoCheckTest, AThirtyMillisecondClockOffsetIsEstimated) {
  const CheckRun r = Feed(Eigen::Quaterniond::Identity(), 0.030,
                          Eigen::Quaterniond::Identity());
  ASSERT_TRUE(r.result.judged);
  EXPECT_FALSE(r.result.rotation_contradicts);
  EXPECT_TRUE(r.result.offset_off);
  EXPECT_NEAR(r.result.offset_correction_s, 0.030, 0.003);
  // The suggested mounting is still the configured one.
  EXPECT_LT(AngleDeg(r.result.best_R_cam_imu, Eigen::Quaterniond::Identity()),
            1.0);
}

}  // namespace
}  // namespace steadiface

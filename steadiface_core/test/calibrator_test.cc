// The offline camera-IMU calibration (issue 16) on simulated recordings with
// known truth: the clock offset, the readout and the IMU's mounting (a signed
// axis permutation plus a small misalignment) are recovered, and recordings
// that cannot determine them are refused with a reason.
#include <cmath>
#include <iostream>
#include <memory>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <ceres/jet.h>

#include "steadiface_core/calibration/calibrator.h"
#include "steadiface_core/calibration/gyro_integral.h"
#include "steadiface_core/check/gyro_video_check.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace {

struct Case {
  std::string preset = "walk";
  int width = 640, height = 360;
  double duration_s = 3.0;
  double offset_s = 0.0, readout_s = 0.02;
  Eigen::Quaterniond mounting = Eigen::Quaterniond::Identity();  // R_cam_imu
  bool mono = false;
  uint64_t seed = 1;
};

// Renders the case and feeds a calibrator that starts from identity, zero
// offset and zero readout (an unconfigured camera).
Status Calibrate(const Case& c, CalibrationResult* r, bool feed_gyro = true,
                 bool black = false) {
  sim::SimulatorOptions o;
  o.data_dir = STEADIFACE_TEST_DATA_DIR;
  EXPECT_TRUE(sim::ApplyPreset(c.preset, &o).ok());
  o.width = c.width;
  o.height = c.height;
  o.duration_s = c.duration_s;
  o.readout_s = c.readout_s;
  o.imu_clock_offset_s = c.offset_s;
  o.seed = c.seed;
  std::unique_ptr<sim::Simulator> s;
  Status st = sim::Simulator::Create(o, &s);
  if (!st.ok()) return st;
  RollingShutterOptions shutter;  // readout 0, first-row stamps
  std::unique_ptr<Calibrator> cal;
  st = Calibrator::Create(s->intrinsics(), shutter,
                          Eigen::Quaterniond::Identity(), 0.0,
                          CalibratorOptions(), &cal);
  if (!st.ok()) return st;
  if (feed_gyro) {
    for (GyroSample g : s->imu()) {
      // The simulator's gyro is in camera axes; an IMU mounted with
      // R_cam_imu reports R_cam_imu^T omega_cam.
      g.angular_velocity = c.mounting.conjugate() * g.angular_velocity;
      cal->AddGyro(g);
    }
  }
  for (int i = 0; i < s->num_frames(); ++i) {
    cv::Mat f;
    sim::SimTruth t;
    st = s->Render(i, &f, &t);
    if (!st.ok()) return st;
    if (black) f.setTo(cv::Scalar::all(0));
    if (c.mono) cv::cvtColor(f, f, cv::COLOR_BGR2GRAY);
    st = cal->AddFrame(f, t.stamp);
    if (!st.ok()) return st;
  }
  return cal->Solve(r);
}

Eigen::Quaterniond Tilted(const Eigen::Quaterniond& P, double deg) {
  return (P * Eigen::Quaterniond(Eigen::AngleAxisd(
                  deg * M_PI / 180.0, Eigen::Vector3d(1, 2, 3).normalized())))
      .normalized();
}

void ExpectRecovered(const Case& c) {
  CalibrationResult r;
  const Status s = Calibrate(c, &r);
  ASSERT_TRUE(s.ok()) << s.message();
  const double rot_err = r.R_cam_imu.angularDistance(c.mounting) * 180.0 / M_PI;
  std::cout << "  offset " << r.time_offset_s * 1e3 << " ms (truth "
            << c.offset_s * 1e3 << ", coarse " << r.coarse_offset_s * 1e3
            << ", sigma " << r.time_offset_sigma_s * 1e3 << "), readout "
            << r.readout_s * 1e3 << " ms (truth " << c.readout_s * 1e3
            << ", sigma " << r.readout_sigma_s * 1e3 << "), rotation error "
            << rot_err << " deg (sigma " << r.rotation_sigma_deg
            << "), misalignment " << r.misalignment_deg << " deg, residual "
            << r.residual_before_px << " -> " << r.residual_after_px << " px, "
            << r.pairs << " pairs, " << r.tracks << " tracks\n";
  EXPECT_NEAR(r.time_offset_s, c.offset_s, 0.001);
  EXPECT_NEAR(r.readout_s, c.readout_s, 0.0015);
  EXPECT_LT(rot_err, 0.5);
  EXPECT_LT(r.residual_after_px, 0.5);
  EXPECT_LT(r.residual_after_px, r.residual_before_px);
}

// The running integral against closed forms: omega(t) = a + b t (exactly
// linear between samples) integrates to a t + b t^2 / 2, and its derivative
// in t (what Ceres sees for the offset and the readout) is omega(t).
TEST(GyroIntegralTest, IntegratesALinearRateExactlyAndDifferentiatesToIt) {
  const Eigen::Vector3d a(0.3, -0.2, 0.1), b(0.5, 0.25, -1.0);
  std::vector<GyroSample> s;
  for (int i = 0; i <= 200; ++i) {
    const double t = 0.005 * i;
    s.push_back({Time(FromSeconds(10.0 + t)), a + b * t});
  }
  const GyroIntegral g(s);
  for (double t : {0.0, 0.1234, 0.5, 0.999}) {
    const Eigen::Vector3d expect = a * t + 0.5 * b * t * t;
    EXPECT_LT((g.At(t) - expect).norm(), 1e-12) << t;
    const ceres::Jet<double, 1> tj(t, 0);
    const auto I = g.At(tj);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(I(k).v[0], a(k) + b(k) * t, 1e-12);
  }
  EXPECT_LT((g.Rate(0.25) - (a + b * 0.25)).norm(), 1e-12);
  // Outside the span it holds the end values.
  EXPECT_LT((g.At(2.0) - g.At(1.0)).norm(), 1e-12);
}

TEST(CalibratorTest, RecoversOffsetReadoutAndAPermutedTiltedMounting) {
  Case c;
  c.offset_s = 0.035;
  c.readout_s = 0.025;
  c.mounting = Tilted(GyroVideoCheck::SignedAxisPermutations()[7], 2.0);
  ExpectRecovered(c);
}

TEST(CalibratorTest, RecoversANegativeOffsetOnAGlobalShutterMonoCamera) {
  Case c;
  c.width = 752;
  c.height = 480;
  c.mono = true;
  c.offset_s = -0.015;
  c.readout_s = 0.0;
  c.seed = 2;
  c.mounting = Tilted(GyroVideoCheck::SignedAxisPermutations()[19], 2.0);
  ExpectRecovered(c);
}

TEST(CalibratorTest, RefusesWhatCannotDetermineTheParameters) {
  CalibrationResult r;
  Case still;
  still.preset = "still";  // no camera rotation at all
  Status s = Calibrate(still, &r);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("too little rotation"), std::string::npos)
      << s.message();

  Case c;
  s = Calibrate(c, &r, /*feed_gyro=*/true, /*black=*/true);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("too few trackable features"), std::string::npos)
      << s.message();

  s = Calibrate(c, &r, /*feed_gyro=*/false);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("no IMU data"), std::string::npos) << s.message();

  Case short_clip;
  short_clip.duration_s = 0.8;
  s = Calibrate(short_clip, &r);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("at least 1 s"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace steadiface

// The visual rotation source: the motion fit on synthetic features with a
// known angular velocity (closed form), and the estimator on rendered
// sequences against the simulator's true rotations.
#include "steadiface_core/visual/visual_rotation.h"

#include <cmath>
#include <iostream>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "sim_util.h"
#include "steadiface_core/common/so3.h"
#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "visual/rotation_fit.h"

namespace steadiface {
namespace {

using testing_util::MakeSimulator;

// Features on a 60 deg wide view, rows read over 20 ms, frames 1/30 s apart,
// moved by a known motion; `outliers` of them moved at random instead.
std::vector<visual::BearingPair> Synthetic(const visual::Motion& m, int n,
                                           double outliers, double noise,
                                           std::mt19937_64* rng) {
  std::uniform_real_distribution<double> u(-0.55, 0.55), v(-0.3, 0.3),
      off(-0.05, 0.05);
  std::normal_distribution<double> g(0.0, noise);
  std::vector<visual::BearingPair> pairs;
  const double T = 1.0 / 30, readout = 0.02;
  for (int i = 0; i < n; ++i) {
    visual::BearingPair p;
    p.b1 = Eigen::Vector3d(u(*rng), v(*rng), 1.0);
    const double t1 = -T / 2 + (p.b1.y() + 0.3) / 0.6 * readout - readout / 2;
    const double t2 = t1 + T;  // the row moves little; its time is what matters
    p.c = t2 - t1;
    p.d = 0.5 * (t2 * t2 - t1 * t1);
    p.n2 = visual::Predict(m, p) + Eigen::Vector2d(g(*rng), g(*rng));
    if (i < outliers * n) p.n2 += Eigen::Vector2d(off(*rng), off(*rng));
    pairs.push_back(p);
  }
  return pairs;
}

TEST(RotationFitTest, RecoversAKnownMotionAndRejectsOutliers) {
  std::mt19937_64 rng(7);
  visual::Motion truth;
  truth << 0.4, -0.7, 0.2, 15.0, -10.0, 5.0;  // rad/s, rad/s^2
  const double f = 554.0;                     // px per normalized unit
  // Noise-free: exact.
  visual::RotationFit fit;
  ASSERT_TRUE(visual::FitMotion(Synthetic(truth, 100, 0.0, 0.0, &rng), f, 2.0,
                                64, 0.0, 1, &fit));
  EXPECT_LT((fit.motion.head<3>() - truth.head<3>()).norm(), 1e-6);
  EXPECT_LT((fit.motion.tail<3>() - truth.tail<3>()).norm(), 1e-3);
  EXPECT_EQ(fit.inliers.size(), 100u);
  // 0.5 px of noise and 30 % outliers (moved by up to 28 px).
  const auto pairs = Synthetic(truth, 150, 0.3, 0.5 / f, &rng);
  ASSERT_TRUE(visual::FitMotion(pairs, f, 2.0, 64, 0.0, 1, &fit));
  EXPECT_LT((fit.motion.head<3>() - truth.head<3>()).norm(), 0.02);
  int outliers_in = 0;
  for (int i : fit.inliers) outliers_in += i < 45 ? 1 : 0;
  EXPECT_LE(outliers_in, 3);  // a few land within 2 px by chance
  EXPECT_GE(static_cast<int>(fit.inliers.size()), 100);
  EXPECT_FALSE(
      visual::FitMotion({pairs[0], pairs[1]}, f, 2.0, 64, 0.0, 1, &fit));
}

// The truth's rotation between two frames' middle rows as an angular
// velocity [rad/s].
Eigen::Vector3d TrueOmega(const sim::SimTruth& a, const sim::SimTruth& b) {
  const Eigen::Quaterniond Ra = a.R_r[a.R_r.size() / 2],
                           Rb = b.R_r[b.R_r.size() / 2];
  return -LogSO3(Rb * Ra.conjugate()) / ToSeconds(b.stamp - a.stamp);
}

TEST(VisualRotationTest, MatchesTheTrueRotationOnRenderedSequences) {
  for (const char* preset : {"pan", "walk", "still"}) {
    SCOPED_TRACE(preset);
    auto s = MakeSimulator(
        preset, [](sim::SimulatorOptions* o) { o->duration_s = 1.5; });
    CameraModel m;
    ASSERT_TRUE(
        CameraModel::Create(s->intrinsics(), CameraModelOptions(), &m).ok());
    std::unique_ptr<VisualRotationEstimator> e;
    ASSERT_TRUE(VisualRotationEstimator::Create(m, s->timing(),
                                                VisualRotationOptions(), &e)
                    .ok());
    cv::Mat frame, grey;
    sim::SimTruth prev, t;
    double se = 0.0;
    int n = 0, valid = 0;
    for (int i = 0; i < s->num_frames(); ++i) {
      ASSERT_TRUE(s->Render(i, &frame, &t).ok());
      cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
      VisualRotation r;
      // The face box from the truth: 1.2 face widths around the head.
      const double w = 1.2 * t.face_scale_px;
      const cv::Rect2d face(t.head_px.x() - w / 2, t.head_px.y() - w / 2, w, w);
      ASSERT_TRUE(e->Process(grey, t.stamp, face, &r).ok());
      if (i == 0) {
        EXPECT_FALSE(r.valid);
      } else {
        se += (r.omega - TrueOmega(prev, t)).squaredNorm();
        ++n;
        valid += r.valid ? 1 : 0;
      }
      prev = t;
    }
    const double rms = std::sqrt(se / n);
    std::cout << "[ " << preset << " ] angular velocity RMS error " << rms
              << " rad/s (" << rms * s->intrinsics().fx / 30.0
              << " px per frame), " << valid << "/" << n << " frames trusted\n";
    EXPECT_EQ(valid, n);
    EXPECT_LT(rms, std::string(preset) == "walk" ? 0.1 : 0.04);
  }
}

TEST(VisualRotationTest, ATexturelessViewIsNotTrustedAndHoldsStill) {
  CameraModel m;
  ASSERT_TRUE(CameraModel::Create(IntrinsicsFromHorizontalFov(640, 360, 1.0),
                                  CameraModelOptions(), &m)
                  .ok());
  RollingShutterOptions rs;
  rs.readout_time_s = 0.02;
  const RowTiming timing(rs, 360);
  std::unique_ptr<VisualRotationEstimator> e;
  ASSERT_TRUE(
      VisualRotationEstimator::Create(m, timing, VisualRotationOptions(), &e)
          .ok());
  cv::Mat wall(360, 640, CV_8UC1, cv::Scalar(128));
  cv::randn(wall, 128, 2);  // sensor noise on a plain wall
  for (int i = 0; i < 5; ++i) {
    VisualRotation r;
    cv::Mat frame = wall.clone();
    cv::randn(frame, 128, 2);
    ASSERT_TRUE(
        e->Process(frame, Time(FromSeconds(1.0 + i / 30.0)), cv::Rect2d(), &r)
            .ok());
    EXPECT_FALSE(r.valid) << i;
    EXPECT_EQ(r.omega, Eigen::Vector3d::Zero());
  }
  VisualRotation r;
  EXPECT_FALSE(e->Process(cv::Mat(10, 10, CV_8UC1), Time(FromSeconds(2.0)),
                          cv::Rect2d(), &r)
                   .ok());
  VisualRotationOptions bad;
  bad.klt_window_px = 20;
  EXPECT_FALSE(VisualRotationEstimator::Create(m, timing, bad, &e).ok());
}

}  // namespace
}  // namespace steadiface

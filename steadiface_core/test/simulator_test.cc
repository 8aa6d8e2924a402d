#include "steadiface_core/sim/simulator.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "sim_util.h"
#include "steadiface_core/common/so3.h"
#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/eval/scorecard.h"
#include "test_util.h"

namespace steadiface {
namespace {

using testing_util::MakeSimulator;

TEST(SimulatorTest, SameSeedGivesByteIdenticalFramesImuAndTruth) {
  auto a = MakeSimulator("occlusion");
  auto b = MakeSimulator("occlusion");
  ASSERT_EQ(a->imu().size(), b->imu().size());
  for (size_t i = 0; i < a->imu().size(); ++i) {
    ASSERT_EQ(a->imu()[i].stamp, b->imu()[i].stamp);
    ASSERT_EQ(a->imu()[i].angular_velocity, b->imu()[i].angular_velocity);
  }
  for (int i : {0, 17, 40}) {
    cv::Mat fa, fb;
    sim::SimTruth ta, tb;
    ASSERT_TRUE(a->Render(i, &fa, &ta).ok());
    ASSERT_TRUE(b->Render(i, &fb, &tb).ok());
    EXPECT_EQ(cv::norm(fa, fb, cv::NORM_INF), 0.0) << i;
    EXPECT_EQ(ta.head_px, tb.head_px);
    EXPECT_EQ(ta.R_r.back().coeffs(), tb.R_r.back().coeffs());
  }
  // Another seed differs.
  auto c = MakeSimulator("occlusion", [](sim::SimulatorOptions* o) { o->seed = 2; });
  EXPECT_NE(c->imu()[10].angular_velocity, a->imu()[10].angular_velocity);
}

TEST(SimulatorTest, WithoutCameraMotionTheHeadCentreFollowsOnlyTheHead) {
  // Still camera, head moving: the background never moves, the head does.
  auto s = MakeSimulator("still");
  Eigen::Vector2d bg0, h0 = s->Truth(0).head_px;
  ASSERT_TRUE(s->BackgroundPixel(0, Eigen::Vector3d(0.1, 0.05, 1), &bg0));
  double head_motion = 0.0;
  for (int i = 1; i < s->num_frames(); i += 7) {
    Eigen::Vector2d bg;
    ASSERT_TRUE(s->BackgroundPixel(i, Eigen::Vector3d(0.1, 0.05, 1), &bg));
    EXPECT_NEAR((bg - bg0).norm(), 0.0, 1e-9);
    head_motion = std::max(head_motion, (s->Truth(i).head_px - h0).norm());
  }
  EXPECT_GT(head_motion, 5.0);
  // And with the head frozen too, the head centre is fixed.
  auto frozen = MakeSimulator("still", [](sim::SimulatorOptions* o) {
    o->head = sim::HeadMotionOptions();
    o->head.bob_amplitude_m = o->head.sway_amplitude_m = o->head.jitter_rms_m = 0.0;
    o->head.yaw_amplitude_rad = o->head.pitch_amplitude_rad = o->head.lean_amplitude_m = 0.0;
  });
  const Eigen::Vector2d f0 = frozen->Truth(0).head_px;
  for (int i = 1; i < frozen->num_frames(); i += 7) {
    EXPECT_NEAR((frozen->Truth(i).head_px - f0).norm(), 0.0, 1e-9);
  }
}

TEST(SimulatorTest, AReliefHeadTurnsAboutItsSkullAndItsFaceMovesAsARealOneDoes) {
  // Still camera; the head only turns (yaw up to 1.2 rad). The pose-invariant
  // head stays put; the face's landmark centre swings sideways by the pivot
  // depth times sin(yaw), in px fx d sin(yaw) / Z; the flat face barely moves.
  auto turning = [](const std::string& model) {
    return MakeSimulator("still", [&model](sim::SimulatorOptions* o) {
      o->head_model = model;
      o->head = sim::HeadMotionOptions();
      o->head.bob_amplitude_m = o->head.sway_amplitude_m = o->head.jitter_rms_m = 0.0;
      o->head.pitch_amplitude_rad = o->head.lean_amplitude_m = 0.0;
      o->head.yaw_amplitude_rad = 1.2;
      o->head.yaw_hz = 0.25;
    });
  };
  auto relief = turning("relief"), flat = turning("flat");
  const double d = relief->options().relief.pivot_depth_m, Z = relief->options().head.distance_m;
  const sim::SimTruth t0 = relief->Truth(0);
  double largest_swing = 0.0, flat_swing = 0.0;
  for (int i = 0; i < relief->num_frames(); i += 5) {
    const sim::SimTruth t = relief->Truth(i);
    EXPECT_NEAR((t.head_px - t0.head_px).norm(), 0.0, 1e-6) << i;
    // The face point swings by d sin(yaw) sideways and d (1 - cos yaw) away
    // from the camera, about the head at lateral offset X0.
    const double fx = relief->intrinsics().fx, cx = relief->intrinsics().cx;
    const double X0 = (t.head_px.x() - cx) * Z / fx;
    const double expected =
        fx * (X0 - d * std::sin(t.yaw)) / (Z + d * (1.0 - std::cos(t.yaw))) - fx * X0 / Z;
    EXPECT_NEAR(t.face_px.x() - t.head_px.x(), expected, 0.3) << i;
    largest_swing = std::max(largest_swing, std::abs(t.face_px.x() - t.head_px.x()));
    const sim::SimTruth f = flat->Truth(i);
    flat_swing = std::max(flat_swing, std::abs(f.face_px.x() - f.head_px.x()));
  }
  EXPECT_GT(largest_swing, 60.0);
  EXPECT_LT(flat_swing, 5.0);
}

TEST(SimulatorTest, PureRotationMovesTheSceneByKRKinv) {
  // Shake only (no translation, no body or head motion), global shutter:
  // every point, near or far, moves by K R K^-1 between frames.
  auto s = MakeSimulator("walk", [](sim::SimulatorOptions* o) {
    o->camera.translation_rms_m = 0.0;
    o->body_bob_m = o->body_sway_m = 0.0;
    o->head.bob_amplitude_m = o->head.sway_amplitude_m = o->head.jitter_rms_m = 0.0;
    o->head.yaw_amplitude_rad = o->head.pitch_amplitude_rad = o->head.lean_amplitude_m = 0.0;
    o->readout_s = 0.0;
  });
  const CameraIntrinsics& k = s->intrinsics();
  const Eigen::Matrix3d K = (Eigen::Matrix3d() << k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1).finished();
  const int i0 = 0, i1 = 30;
  const sim::SimTruth t0 = s->Truth(i0), t1 = s->Truth(i1);
  const Eigen::Matrix3d H =
      K * (t1.R_r[0] * t0.R_r[0].conjugate()).toRotationMatrix() * K.inverse();
  // Background direction.
  Eigen::Vector2d b0, b1;
  ASSERT_TRUE(s->BackgroundPixel(i0, Eigen::Vector3d(-0.1, 0.08, 1), &b0));
  ASSERT_TRUE(s->BackgroundPixel(i1, Eigen::Vector3d(-0.1, 0.08, 1), &b1));
  EXPECT_NEAR(((H * b0.homogeneous()).hnormalized() - b1).norm(), 0.0, 1e-6);
  // The head (0.45 m away) too: a pure rotation has no parallax.
  EXPECT_NEAR(((H * t0.head_px.homogeneous()).hnormalized() - t1.head_px).norm(), 0.0, 1e-6);
  // Pixels: frame 0 warped by H matches frame 30 where both are defined.
  cv::Mat f0, f1, w;
  sim::SimTruth tr;
  ASSERT_TRUE(s->Render(i0, &f0, &tr).ok());
  ASSERT_TRUE(s->Render(i1, &f1, &tr).ok());
  cv::Matx33d Hc;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Hc(r, c) = H(r, c);
  cv::warpPerspective(f0, w, Hc, f0.size(), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  const cv::Rect inner(40, 40, f0.cols - 80, f0.rows - 80);
  const double psnr = cv::PSNR(w(inner), f1(inner));
  EXPECT_GT(psnr, 28.0);
}

TEST(SimulatorTest, IntegratedImuReproducesTheTrueOrientation) {
  auto s = MakeSimulator("walk", [](sim::SimulatorOptions* o) { o->imu_clock_offset_s = 0.012; });
  OrientationTimelineOptions to;
  to.imu_time_offset_s = 0.012;
  OrientationTimeline tl(to);
  for (const auto& g : s->imu()) ASSERT_EQ(tl.AddSample(g), SampleResult::kAccepted);
  // Relative rotations from the first frame: bias (~2e-3 rad/s) and noise
  // (2e-3 rad/s at 200 Hz) bound the error over 3 s by ~8e-3 rad.
  const double ta = 0.1;
  Eigen::Quaterniond Ra;
  ASSERT_TRUE(QuerySucceeded(tl.RealRotation(Time(FromSeconds(ta)), &Ra)));
  double worst = 0.0;
  for (double t = 0.2; t < 2.9; t += 0.1) {
    Eigen::Quaterniond Rt;
    ASSERT_TRUE(QuerySucceeded(tl.RealRotation(Time(FromSeconds(t)), &Rt)));
    const Eigen::Quaterniond est = Rt * Ra.conjugate();
    const Eigen::Quaterniond truth =
        s->CameraPose(t).R.conjugate() * s->CameraPose(ta).R;
    worst = std::max(worst, AngleBetween(est, truth));
  }
  EXPECT_LT(worst, 8e-3) << worst;
}

// The recorded trace played k times as fast: the orientation at t is the
// normal-speed one at k t (same amplitude), the IMU reads k times the
// angular velocity, and integrating it reproduces the true orientation.
TEST(SimulatorTest, RealGyroSpeedPlaysTheTraceFasterWithTheSameAmplitude) {
  auto normal = MakeSimulator("run", [](sim::SimulatorOptions* o) { o->gyro_noise = 0.0; });
  auto fast = MakeSimulator("run", [](sim::SimulatorOptions* o) {
    o->gyro_noise = 0.0;
    o->real_gyro_speed = 2.5;
  });
  ASSERT_NE(normal, nullptr);
  ASSERT_NE(fast, nullptr);
  for (double t = 0.0; t < 1.1; t += 0.05) {
    EXPECT_LT(AngleBetween(fast->CameraPose(t).R, normal->CameraPose(2.5 * t).R), 1e-9) << t;
  }
  OrientationTimeline tl{OrientationTimelineOptions()};
  for (const auto& g : fast->imu()) ASSERT_EQ(tl.AddSample(g), SampleResult::kAccepted);
  const double ta = 0.1;
  Eigen::Quaterniond Ra;
  ASSERT_TRUE(QuerySucceeded(tl.RealRotation(Time(FromSeconds(ta)), &Ra)));
  double worst = 0.0, travelled = 0.0;
  for (double t = 0.2; t < 2.9; t += 0.1) {
    Eigen::Quaterniond Rt;
    ASSERT_TRUE(QuerySucceeded(tl.RealRotation(Time(FromSeconds(t)), &Rt)));
    const Eigen::Quaterniond truth =
        fast->CameraPose(t).R.conjugate() * fast->CameraPose(ta).R;
    worst = std::max(worst, AngleBetween(Rt * Ra.conjugate(), truth));
    travelled = std::max(travelled, AngleBetween(truth, Eigen::Quaterniond::Identity()));
  }
  // Integration error only (bias ~2e-3 rad/s over 3 s), against rotations
  // of several degrees.
  EXPECT_LT(worst, 8e-3) << worst;
  EXPECT_GT(travelled, 0.05);
  sim::SimulatorOptions o;
  o.data_dir = STEADIFACE_TEST_DATA_DIR;
  o.use_real_gyro = true;
  o.real_gyro_speed = 0.0;
  std::unique_ptr<sim::Simulator> s;
  EXPECT_FALSE(sim::Simulator::Create(o, &s).ok());
}

// The truth behind the composite: the scene without the subject equals the
// frame wherever the subject does not cover it, differs under it, and the
// coverage agrees with SubjectCovers; a passer-by is part of the scene.
TEST(SimulatorTest, TruthLayersAreTheFrameWithoutTheSubjectAndItsCoverage) {
  for (const std::string preset : {"vlog", "passer_by"}) {
    auto s = MakeSimulator(preset);
    ASSERT_NE(s, nullptr);
    const int i = s->num_frames() / 2;
    cv::Mat frame, scene, alpha;
    sim::SimTruth truth;
    ASSERT_TRUE(s->Render(i, &frame, &truth).ok());
    ASSERT_TRUE(s->RenderTruthLayers(i, &scene, &alpha).ok());
    ASSERT_EQ(alpha.type(), CV_8UC1);
    cv::Mat diff;
    cv::absdiff(frame, scene, diff);
    cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
    EXPECT_EQ(cv::countNonZero(diff & (alpha == 0)), 0) << preset;
    EXPECT_GT(cv::countNonZero(diff & (alpha == 255)), 0.5 * cv::countNonZero(alpha == 255)) << preset;
    int agree = 0, n = 0;
    for (int y = 5; y < alpha.rows; y += 10) {
      for (int x = 5; x < alpha.cols; x += 10) {
        const uchar a = alpha.at<uchar>(y, x);
        if (a > 20 && a < 235) continue;  // the soft edge
        agree += (a >= 128) == s->SubjectCovers(i, Eigen::Vector2d(x, y));
        ++n;
      }
    }
    EXPECT_GT(agree, 0.98 * n) << preset;
  }
  // The passer-by, mid-way, is behind the subject: in the scene, not in the
  // coverage; rendering it changes the scene.
  auto with = MakeSimulator("passer_by");
  auto without = MakeSimulator("passer_by", [](sim::SimulatorOptions* o) {
    o->passer_by_start_s = -1;
  });
  cv::Mat a, b, alpha_a, alpha_b;
  ASSERT_TRUE(with->RenderTruthLayers(30, &a, &alpha_a).ok());
  ASSERT_TRUE(without->RenderTruthLayers(30, &b, &alpha_b).ok());
  EXPECT_GT(cv::norm(a, b, cv::NORM_L1), 0.0);
  EXPECT_EQ(cv::norm(alpha_a, alpha_b, cv::NORM_INF), 0.0);
}

// The robot preset is its own camera (640x480, 60 deg) whatever size is
// asked for, with the person 2.5 m away: a face 30-40 px wide, the size a
// robot's camera sees.
TEST(SimulatorTest, RobotPresetSeesASmallFace) {
  auto s = MakeSimulator("robot");
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->intrinsics().width, 640);
  EXPECT_EQ(s->intrinsics().height, 480);
  EXPECT_NEAR(s->intrinsics().fx, 320.0 / std::tan(M_PI / 6.0), 1e-6);
  for (int i : {0, 45, 89}) {
    cv::Mat frame;
    sim::SimTruth t;
    ASSERT_TRUE(s->Render(i, &frame, &t).ok()) << i;
    EXPECT_TRUE(t.head_in_view) << i;
    EXPECT_GT(t.face_scale_px, 28.0) << i;
    EXPECT_LT(t.face_scale_px, 40.0) << i;
  }
}

TEST(SimulatorTest, PresetsAndErrors) {
  for (const auto& p : sim::PresetNames()) {
    auto s = MakeSimulator(p);
    ASSERT_NE(s, nullptr) << p;
    EXPECT_EQ(s->num_frames(), p == "dropout" ? 210 : 90) << p;  // dropout: at least 7 s
  }
  sim::SimulatorOptions o;
  EXPECT_FALSE(sim::ApplyPreset("nope", &o).ok());
  o.data_dir = "/nonexistent";
  std::unique_ptr<sim::Simulator> s;
  EXPECT_FALSE(sim::Simulator::Create(o, &s).ok());
}

}  // namespace
}  // namespace steadiface

namespace steadiface {
namespace {

// The vlog preset: a head with neck and shoulders at arm's length. The
// subject mask (SubjectCovers) holds the face and the torso below it, not
// the background beside them, and the torso moves with the head.
TEST(SimulatorTest, VlogHasATorsoUnderTheFaceAndASubjectMask) {
  auto s = MakeSimulator("vlog");
  ASSERT_TRUE(s->options().render_torso);
  for (int i : {0, 45}) {
    const sim::SimTruth t = s->Truth(i);
    ASSERT_TRUE(t.head_in_view);
    const double w = t.face_scale_px;
    EXPECT_TRUE(s->SubjectCovers(i, t.head_px));
    // Shoulders: 1.2 face widths below and 0.6 to the side of the face's
    // centre (outside the face billboard's ellipse).
    EXPECT_TRUE(s->SubjectCovers(i, t.head_px + Eigen::Vector2d(0.6 * w, 1.2 * w)));
    EXPECT_TRUE(s->SubjectCovers(i, t.head_px + Eigen::Vector2d(-0.6 * w, 1.2 * w)));
    // Background beside the head and above the shoulders.
    EXPECT_FALSE(s->SubjectCovers(i, t.head_px + Eigen::Vector2d(1.4 * w, -0.3 * w)));
    EXPECT_FALSE(s->SubjectCovers(i, Eigen::Vector2d(5, 5)));
  }
  // The walk preset has no torso: below the face is background.
  auto walk = MakeSimulator("walk");
  const sim::SimTruth t = walk->Truth(0);
  EXPECT_FALSE(walk->SubjectCovers(0, t.head_px + Eigen::Vector2d(0.6 * t.face_scale_px,
                                                                    1.2 * t.face_scale_px)));
  // The rendered torso is there: the pixels under the shoulders' point
  // differ from a render without it.
  sim::SimulatorOptions no_torso = s->options();
  no_torso.render_torso = false;
  std::unique_ptr<sim::Simulator> bare;
  ASSERT_TRUE(sim::Simulator::Create(no_torso, &bare).ok());
  cv::Mat a, b;
  sim::SimTruth ta, tb;
  ASSERT_TRUE(s->Render(0, &a, &ta).ok());
  ASSERT_TRUE(bare->Render(0, &b, &tb).ok());
  const Eigen::Vector2d p =
      ta.head_px + Eigen::Vector2d(0.6 * ta.face_scale_px, 1.2 * ta.face_scale_px);
  if (p.y() < a.rows - 1) {
    const cv::Vec3b ca = a.at<cv::Vec3b>(static_cast<int>(p.y()), static_cast<int>(p.x()));
    const cv::Vec3b cb = b.at<cv::Vec3b>(static_cast<int>(p.y()), static_cast<int>(p.x()));
    EXPECT_NE(ca, cb);
  }
}

}  // namespace
}  // namespace steadiface

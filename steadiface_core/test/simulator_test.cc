#include "steadiface_core/sim/simulator.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/so3.h"
#include "sim_util.h"
#include "test_util.h"

namespace steadiface {
namespace {

std::unique_ptr<sim::Simulator> Make(const std::string& preset,
                                     std::function<void(sim::SimulatorOptions*)> tweak = {}) {
  return testing_util::MakeSimulator(preset, tweak);
}

TEST(SimulatorTest, SameSeedGivesByteIdenticalFramesImuAndTruth) {
  auto a = Make("occlusion");
  auto b = Make("occlusion");
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
  auto c = Make("occlusion", [](sim::SimulatorOptions* o) { o->seed = 2; });
  EXPECT_NE(c->imu()[10].angular_velocity, a->imu()[10].angular_velocity);
}

TEST(SimulatorTest, WithoutCameraMotionTheHeadCentreFollowsOnlyTheHead) {
  // Still camera, head moving: the background never moves, the head does.
  auto s = Make("still");
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
  auto frozen = Make("still", [](sim::SimulatorOptions* o) {
    o->head = sim::HeadMotionOptions();
    o->head.bob_amplitude_m = o->head.sway_amplitude_m = o->head.jitter_rms_m = 0.0;
    o->head.yaw_amplitude_rad = o->head.pitch_amplitude_rad = o->head.lean_amplitude_m = 0.0;
  });
  const Eigen::Vector2d f0 = frozen->Truth(0).head_px;
  for (int i = 1; i < frozen->num_frames(); i += 7) {
    EXPECT_NEAR((frozen->Truth(i).head_px - f0).norm(), 0.0, 1e-9);
  }
}

TEST(SimulatorTest, PureRotationMovesTheSceneByKRKinv) {
  // Shake only (no translation, no body or head motion), global shutter:
  // every point, near or far, moves by K R K^-1 between frames.
  auto s = Make("walk", [](sim::SimulatorOptions* o) {
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
  auto s = Make("walk", [](sim::SimulatorOptions* o) { o->imu_clock_offset_s = 0.012; });
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
  auto normal = Make("run", [](sim::SimulatorOptions* o) { o->gyro_noise = 0.0; });
  auto fast = Make("run", [](sim::SimulatorOptions* o) {
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

TEST(SimulatorTest, PresetsAndErrors) {
  for (const auto& p : sim::PresetNames()) {
    auto s = Make(p);
    ASSERT_NE(s, nullptr) << p;
    EXPECT_EQ(s->num_frames(), 90);
  }
  sim::SimulatorOptions o;
  EXPECT_FALSE(sim::ApplyPreset("nope", &o).ok());
  o.data_dir = "/nonexistent";
  std::unique_ptr<sim::Simulator> s;
  EXPECT_FALSE(sim::Simulator::Create(o, &s).ok());
}

// ---------- Scorecard sanity ----------

TEST(ScorecardTest, IdentityOnAStillSceneScoresZeroJitter) {
  auto s = Make("still", [](sim::SimulatorOptions* o) {
    o->head.bob_amplitude_m = o->head.sway_amplitude_m = o->head.jitter_rms_m = 0.0;
    o->head.yaw_amplitude_rad = o->head.pitch_amplitude_rad = o->head.lean_amplitude_m = 0.0;
  });
  std::unique_ptr<eval::Scorecard> scorecard;
  ASSERT_TRUE(eval::MakeScorecard(*s, PipelineOptions(), &scorecard).ok());
  eval::Scorecard& card = *scorecard;
  for (int i = 0; i < s->num_frames(); ++i) card.Add(i, eval::FrameWarp());
  const eval::Score sc = card.Compute();
  EXPECT_NEAR(sc.head_jitter_px, 0.0, 1e-9);
  EXPECT_NEAR(sc.background_jitter_px, 0.0, 1e-9);
  EXPECT_EQ(sc.undefined_fraction, 0.0);
  EXPECT_EQ(sc.distortion, 1.0);
  EXPECT_EQ(sc.cropping, 1.0);
}

TEST(ScorecardTest, AWarpThatCancelsTheTrueMotionScoresNearZero) {
  auto s = Make("walk");
  std::unique_ptr<eval::Scorecard> scorecard;
  ASSERT_TRUE(eval::MakeScorecard(*s, PipelineOptions(), &scorecard).ok());
  eval::Scorecard& card = *scorecard;
  const Eigen::Quaterniond R0 = s->Truth(0).R_r[7];
  for (int i = 0; i < s->num_frames(); ++i) {
    const sim::SimTruth t = s->Truth(i);
    eval::FrameWarp w;
    w.kind = eval::FrameWarp::Kind::kPose;
    w.R_v = R0;  // a virtual camera that never rotates
    w.rows = RowRotations::FromTable(t.R_r, s->intrinsics().height);
    card.Add(i, w);
  }
  // The true per-row rotations cancel the camera's rotation exactly (up to
  // the interpolation between the 16 truth rows): the far background stands
  // still in the output.
  const eval::Score sc = card.Compute();
  EXPECT_LT(sc.background_jitter_px, 0.05) << sc.background_jitter_px;
  EXPECT_EQ(sc.undefined_fraction, 0.0);
}

TEST(ScorecardTest, AddedJitterRaisesTheScoreByTheExpectedAmount) {
  auto s = Make("still", [](sim::SimulatorOptions* o) {
    o->head.bob_amplitude_m = o->head.sway_amplitude_m = o->head.jitter_rms_m = 0.0;
    o->head.yaw_amplitude_rad = o->head.pitch_amplitude_rad = o->head.lean_amplitude_m = 0.0;
  });
  std::unique_ptr<eval::Scorecard> scorecard;
  ASSERT_TRUE(eval::MakeScorecard(*s, PipelineOptions(), &scorecard).ok());
  eval::Scorecard& card = *scorecard;
  const double a = 4.0;  // px amplitude at 5 Hz (an exact bin for 90 frames at 30 fps)
  for (int i = 0; i < s->num_frames(); ++i) {
    eval::FrameWarp w;
    w.kind = eval::FrameWarp::Kind::kHomography;
    w.H = Eigen::Matrix3d::Identity();
    w.H(0, 2) = a * std::sin(2 * M_PI * 5.0 * i / 30.0);
    card.Add(i, w);
  }
  const eval::Score sc = card.Compute();
  // RMS of a sinusoid: a / sqrt(2).
  EXPECT_NEAR(sc.head_jitter_px, a / std::sqrt(2.0), 0.02 * a);
  EXPECT_NEAR(sc.background_jitter_px, a / std::sqrt(2.0), 0.02 * a);
  // Shifting exposes the border on every frame but those with zero shift
  // (one in three).
  EXPECT_GT(sc.undefined_fraction, 0.6);
}

// The pan preset's intentional pan alone, with no shake, scores about 4 px
// of background "jitter" in the input: its rate ramps in over 2 s, which
// the linear detrend does not remove (docs/evaluation.md, pan). So on pan
// the background column mostly measures how a method follows the pan.
TEST(ScorecardTest, ThePanItselfScoresMostOfThePanPresetsBackgroundJitter) {
  auto input_background = [](const sim::Simulator& s) {
    std::unique_ptr<eval::Scorecard> card;
    EXPECT_TRUE(eval::MakeScorecard(s, PipelineOptions(), &card).ok());
    for (int i = 0; i < s.num_frames(); ++i) card->Add(i, eval::FrameWarp());
    return card->Compute().background_jitter_px;
  };
  const double pan_only = input_background(*Make("pan", [](sim::SimulatorOptions* o) {
    o->camera.shake_rms_rad = 0.0;
    o->camera.translation_rms_m = 0.0;
  }));
  const double preset = input_background(*Make("pan"));
  std::cout << "[ pan ] input background jitter: pan alone " << pan_only << " px, preset "
            << preset << " px\n";
  EXPECT_NEAR(pan_only, 4.0, 0.3);
  EXPECT_GT(pan_only, 0.7 * preset);
  EXPECT_LT(pan_only, preset);
}

// A still camera with a moving head: the head moves against a still
// background by the head's own motion. Holding the head (an image shift that
// cancels it) moves the background by exactly that much; a global shake
// moves both alike. The relative jitter is the same for all three warps, and
// the background floor is 0 for the input and the whole relative jitter when
// the head is held.
TEST(ScorecardTest, RelativeJitterIsFixedByTheSceneAndBoundsTheBackground) {
  auto s = Make("still");
  const Eigen::Vector2d head0 = s->Truth(0).head_px;
  auto score = [&](auto shift_of_frame) {
    std::unique_ptr<eval::Scorecard> card;
    EXPECT_TRUE(eval::MakeScorecard(*s, PipelineOptions(), &card).ok());
    for (int i = 0; i < s->num_frames(); ++i) {
      eval::FrameWarp w;
      w.kind = eval::FrameWarp::Kind::kHomography;
      w.H.topRightCorner<2, 1>() = shift_of_frame(i);
      card->Add(i, w);
    }
    return card->Compute();
  };
  const eval::Score input = score([](int) { return Eigen::Vector2d::Zero(); });
  const eval::Score held = score([&](int i) -> Eigen::Vector2d {
    return head0 - s->Truth(i).head_px;
  });
  const double a = 4.0;  // a 5 Hz global shake (an exact bin for 90 frames)
  const eval::Score shaken = score([&](int i) -> Eigen::Vector2d {
    return Eigen::Vector2d(a * std::sin(2 * M_PI * 5.0 * i / 30.0), 0.0);
  });
  ASSERT_GT(input.head_jitter_px, 5.0);
  EXPECT_NEAR(input.background_jitter_px, 0.0, 1e-9);
  EXPECT_NEAR(input.relative_jitter_px, input.head_jitter_px, 1e-6);
  EXPECT_NEAR(input.background_floor_px, 0.0, 1e-6);

  EXPECT_LT(held.head_jitter_px, 1e-6);
  EXPECT_NEAR(held.relative_jitter_px, input.relative_jitter_px, 1e-6);
  EXPECT_NEAR(held.background_jitter_px, input.head_jitter_px, 1e-6);
  EXPECT_NEAR(held.background_floor_px, held.background_jitter_px, 1e-6);

  EXPECT_NEAR(shaken.background_jitter_px, a / std::sqrt(2.0), 0.02 * a);
  EXPECT_GT(shaken.head_jitter_px, input.head_jitter_px + 0.1);
  EXPECT_NEAR(shaken.relative_jitter_px, input.relative_jitter_px, 1e-6);
}

// ---------- The full pipeline on rendered presets (issue: stabilizer) ----

struct PresetResult {
  eval::Score none, gyro, full;
};

// `crop_ratio` < 0: the package default; `duration_s` < 0: the simulator's.
PresetResult Score(const std::string& preset, double crop_ratio = -1.0,
                   double duration_s = -1.0) {
  auto s = Make(preset, [duration_s](sim::SimulatorOptions* o) {
    if (duration_s > 0.0) o->duration_s = duration_s;
  });
  PresetResult r;
  for (eval::Method method : {eval::Method::kNone, eval::Method::kGyroOnly, eval::Method::kSteadiface}) {
    PipelineOptions po = eval::OptionsFor(*s, method);
    if (crop_ratio >= 0.0) po.warp.output.crop_ratio = crop_ratio;
    std::unique_ptr<eval::Scorecard> card;
    Status st = eval::MakeScorecard(*s, po, &card);
    if (st.ok()) st = eval::RunMethod(*s, method, po, false, card.get(), nullptr);
    EXPECT_TRUE(st.ok()) << st.message();
    if (!st.ok()) continue;
    (method == eval::Method::kNone ? r.none : method == eval::Method::kGyroOnly ? r.gyro : r.full) =
        card->Compute();
  }
  std::cout << "[ " << preset << " ] head jitter none " << r.none.head_jitter_px << " / gyro-only "
            << r.gyro.head_jitter_px << " / steadiface " << r.full.head_jitter_px
            << " px; background " << r.none.background_jitter_px << " / "
            << r.gyro.background_jitter_px << " / " << r.full.background_jitter_px
            << " px; head-vs-background " << r.none.relative_jitter_px << " / "
            << r.gyro.relative_jitter_px << " / " << r.full.relative_jitter_px
            << " px; background floor " << r.full.background_floor_px
            << " px; undefined " << r.gyro.undefined_fraction << " / "
            << r.full.undefined_fraction << "\n";
  return r;
}

TEST(PipelinePresetTest, WalkBeatsGyroOnlyOnTheHeadAndKeepsTheBackground) {
  const PresetResult r = Score("walk");
  EXPECT_LE(r.full.head_jitter_px, 0.5 * r.gyro.head_jitter_px);
  EXPECT_LE(r.full.head_jitter_px, 0.3 * r.none.head_jitter_px);
  EXPECT_LE(r.gyro.background_jitter_px, 0.2 * r.none.background_jitter_px);
  EXPECT_LE(r.full.background_jitter_px, 0.85 * r.none.background_jitter_px);
  EXPECT_EQ(r.full.undefined_fraction, 0.0);
}

// One rotation and offset per frame moves the head and the far background
// alike, so the head's jitter relative to the background is fixed by the
// scene (up to the zoom and the rolling-shutter correction), and holding the
// head costs the background at least that much. Steadiface pays little more
// than that floor. On pan the person turns with the phone: the head moves
// more against the background than the camera shakes, so no such warp can
// hold the head to 0.3x the input's jitter and keep the background below the
// input's.
TEST(PipelinePresetTest, HoldingTheHeadCostsTheBackgroundLittleMoreThanGeometryRequires) {
  const double zoom = 1.0 / (1.0 - 2.0 * OutputOptions().crop_ratio);
  for (const std::string preset : {"walk", "pan"}) {
    SCOPED_TRACE(preset);
    const PresetResult r = Score(preset);
    const double conserved = zoom * r.none.relative_jitter_px;
    EXPECT_NEAR(r.gyro.relative_jitter_px, conserved, 0.12 * conserved);
    EXPECT_NEAR(r.full.relative_jitter_px, conserved, 0.12 * conserved);
    EXPECT_LE(r.full.background_jitter_px, 1.25 * r.full.background_floor_px);
    if (preset == "pan") {
      EXPECT_GT(conserved - 0.3 * r.none.head_jitter_px, r.none.background_jitter_px);
    }
  }
}

TEST(PipelinePresetTest, RunWithTheRealGyroTrace) {
  // The whole recorded running trace (9.9 s) at the default (the paper's)
  // 15 % crop: the bars hold (measured: steadiface's head jitter
  // 0.17x the input's and 0.31x gyro-only's; gyro-only removes 59 % of the
  // background jitter, steadiface 59 %).
  const PresetResult r = Score("run", -1.0, 9.8);
  EXPECT_LE(r.full.head_jitter_px, 0.3 * r.none.head_jitter_px);
  EXPECT_LE(r.full.head_jitter_px, 0.5 * r.gyro.head_jitter_px);
  EXPECT_LE(r.gyro.background_jitter_px, 0.5 * r.none.background_jitter_px);
  EXPECT_LE(r.full.background_jitter_px, 0.5 * r.none.background_jitter_px);
  EXPECT_EQ(r.full.undefined_fraction, 0.0);
  EXPECT_EQ(r.gyro.undefined_fraction, 0.0);
}

TEST(PipelinePresetTest, ALargerCropRemovesMoreOfTheRunningShake) {
  // The crop margin bounds what any warp can remove; on the running trace's
  // first 3 s (one 0.12 rad tilt larger than a 10 % margin) the head jitter
  // falls as the crop grows (measured 12.4 / 8.0 / 4.4 px at 10 / 15 / 20 %,
  // input 24.7 px).
  double previous = 1e9;
  for (double crop : {0.1, 0.15, 0.2}) {
    SCOPED_TRACE(crop);
    const PresetResult r = Score("run", crop);
    EXPECT_LT(r.full.head_jitter_px, 0.8 * previous);
    EXPECT_LE(r.full.head_jitter_px, 0.55 * r.none.head_jitter_px);
    EXPECT_EQ(r.full.undefined_fraction, 0.0);
    previous = r.full.head_jitter_px;
  }
}

// The face leaves the frame sideways and comes back (issue: simulator,
// events; issue: stabilizer, no face): the truth flags the frames, the
// stabilizer fades to gyro-only while the face is out and back in after it
// returns, with bounded per-frame weight steps and no undefined pixels.
TEST(PipelinePresetTest, FaceLeavingAndReenteringFadesWithoutJumps) {
  auto s = Make("walk", [](sim::SimulatorOptions* o) {
    o->duration_s = 4.0;
    o->face_out_start_s = 1.2;
    o->face_out_end_s = 2.4;
  });
  int out_frames = 0;
  for (int i = 0; i < s->num_frames(); ++i) out_frames += s->Truth(i).face_out ? 1 : 0;
  EXPECT_FALSE(s->Truth(0).face_out);
  EXPECT_FALSE(s->Truth(s->num_frames() - 1).face_out);
  EXPECT_GT(out_frames, 20);
  const PipelineOptions po = eval::OptionsFor(*s, eval::Method::kSteadiface);
  std::unique_ptr<eval::Scorecard> card;
  ASSERT_TRUE(eval::MakeScorecard(*s, po, &card).ok());
  std::vector<StabilizerFrame> frames;
  ASSERT_TRUE(eval::RunMethod(*s, eval::Method::kSteadiface, po, false, card.get(), &frames).ok());
  ASSERT_EQ(static_cast<int>(frames.size()), s->num_frames());
  double max_step = 0.0, min_fit_out = 1.0, max_fit_back = 0.0;
  int used_while_out = 0;
  for (size_t i = 0; i < frames.size(); ++i) {
    const double t = ToSeconds(frames[i].stamp - frames[0].stamp);
    if (i > 0) max_step = std::max(max_step, std::abs(frames[i].factors.fit - frames[i - 1].factors.fit));
    // Fully out of view (the 0.4 s ramp done) and 0.5 s later: faded out.
    if (t > 1.6 + 0.5 && t < 2.4) min_fit_out = std::min(min_fit_out, frames[i].factors.fit);
    if (t > 1.6 + 0.5 && t < 2.4 && frames[i].flags.face_used) ++used_while_out;
    if (t > 3.3) max_fit_back = std::max(max_fit_back, frames[i].factors.fit);
  }
  std::cout << "[ face leaves ] " << out_frames << " frames out of view; w_f factor while out "
            << min_fit_out << ", after return " << max_fit_back << ", max step " << max_step
            << "\n";
  EXPECT_LT(min_fit_out, 0.15);     // gyro-only while the face is away
  EXPECT_GT(max_fit_back, 0.5);     // the face is back and used again
  EXPECT_EQ(used_while_out, 0);
  EXPECT_LT(max_step, 0.2);         // fades, never jumps
  EXPECT_EQ(card->Compute().undefined_fraction, 0.0);
}

// A global brightness change mid-sequence (auto exposure): the face stays
// tracked through it, and the head stays steadier than gyro-only.
TEST(PipelinePresetTest, BrightnessChangeKeepsTheFace) {
  auto s = Make("walk", [](sim::SimulatorOptions* o) { o->brightness_change_s = 1.5; });
  int changed = 0;
  for (int i = 0; i < s->num_frames(); ++i) changed += s->Truth(i).brightness_changed ? 1 : 0;
  EXPECT_GT(changed, 10);
  eval::Score full, gyro;
  for (eval::Method method : {eval::Method::kGyroOnly, eval::Method::kSteadiface}) {
    const PipelineOptions po = eval::OptionsFor(*s, method);
    std::unique_ptr<eval::Scorecard> card;
    ASSERT_TRUE(eval::MakeScorecard(*s, po, &card).ok());
    std::vector<StabilizerFrame> frames;
    ASSERT_TRUE(eval::RunMethod(*s, method, po, false, card.get(), &frames).ok());
    (method == eval::Method::kSteadiface ? full : gyro) = card->Compute();
    if (method == eval::Method::kSteadiface) {
      int used_after = 0, after = 0;
      for (size_t i = 0; i < frames.size(); ++i) {
        if (ToSeconds(frames[i].stamp - frames[0].stamp) > 1.6) {
          ++after;
          used_after += frames[i].flags.face_used ? 1 : 0;
        }
      }
      EXPECT_GT(used_after, 0.9 * after) << "face lost after the brightness change";
    }
  }
  EXPECT_LT(full.head_jitter_px, 0.5 * gyro.head_jitter_px);
}

TEST(PipelinePresetTest, EveryPresetHasNoUndefinedPixels) {
  for (const std::string& p : {"still", "pan", "occlusion", "two_faces", "turn_away"}) {
    const PresetResult r = Score(p);
    EXPECT_EQ(r.full.undefined_fraction, 0.0) << p;
    EXPECT_EQ(r.gyro.undefined_fraction, 0.0) << p;
    EXPECT_GT(r.full.distortion, 0.9) << p;
  }
}

}  // namespace
}  // namespace steadiface

namespace steadiface {
namespace {

// The vlog preset: a head with neck and shoulders at arm's length. The
// subject mask (SubjectCovers) holds the face and the torso below it, not
// the background beside them, and the torso moves with the head.
TEST(SimulatorTest, VlogHasATorsoUnderTheFaceAndASubjectMask) {
  auto s = Make("vlog");
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
  auto walk = Make("walk");
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

// The full pipeline on rendered presets against gyro-only and the input:
// head and background jitter, the crop, a face leaving and coming back, a
// brightness change, no undefined pixels.
#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "score_util.h"
#include "sim_util.h"
#include "steadiface_core/common/so3.h"
#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/simulator.h"
#include "test_util.h"

namespace steadiface {
namespace {

using testing_util::MakeSimulator;

// The method with its default options on `s`, scored; `frames` gets the
// stabilizer's record.
eval::Score ScoreMethod(const sim::Simulator& s, eval::Method method,
                        std::vector<StabilizerFrame>* frames) {
  return testing_util::ScoreRun(s, method, {}, frames);
}

struct PresetResult {
  eval::Score none, gyro, full;
};

// `crop_ratio` < 0: the package default; `duration_s` < 0: the simulator's.
PresetResult Score(const std::string& preset, double crop_ratio = -1.0,
                   double duration_s = -1.0) {
  auto s = MakeSimulator(preset, [duration_s](sim::SimulatorOptions* o) {
    if (duration_s > 0.0) o->duration_s = duration_s;
  });
  PresetResult r;
  for (eval::Method method : {eval::Method::kNone, eval::Method::kGyroOnly, eval::Method::kSteadiface}) {
    PipelineOptions po = eval::OptionsFor(*s, method);
    if (crop_ratio >= 0.0) po.warp.output.crop_ratio = crop_ratio;
    std::unique_ptr<eval::Scorecard> card;
    Status st = eval::MakeScorecard(*s, po, &card);
    if (st.ok()) st = eval::RunMethod(*s, method, po, card.get());
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
// The evaluation's perfect tracker (steadiface_evaluate --true-head): the
// simulator's true head centre in place of the tracker's. On walk it holds
// the head better than the tracker does (1.01 against 1.51 px at seed 1),
// so what the hook hands over is where the scorer looks.
TEST(PipelinePresetTest, TheTrueHeadCentreIsHeldBetterThanTheTrackers) {
  auto s = MakeSimulator("walk");
  const PipelineOptions po = eval::OptionsFor(*s, eval::Method::kSteadiface);
  eval::Score score[2];
  for (int true_head = 0; true_head < 2; ++true_head) {
    std::unique_ptr<eval::Scorecard> card;
    Status st = eval::MakeScorecard(*s, po, &card);
    if (st.ok()) {
      eval::RunMethodOptions run;
      run.true_head = true_head == 1;
      st = eval::RunMethod(*s, eval::Method::kSteadiface, po, card.get(), run);
    }
    ASSERT_TRUE(st.ok()) << st.message();
    score[true_head] = card->Compute();
  }
  std::cout << "[ walk ] head: tracker " << score[0].head_jitter_px << " px, true head "
            << score[1].head_jitter_px << " px\n";
  EXPECT_LT(score[1].head_jitter_px, 0.75 * score[0].head_jitter_px);
}

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
  auto s = MakeSimulator("walk", [](sim::SimulatorOptions* o) {
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
  eval::RunMethodOptions run;
  run.frames = &frames;
  ASSERT_TRUE(eval::RunMethod(*s, eval::Method::kSteadiface, po, card.get(), run).ok());
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
  auto s = MakeSimulator("walk", [](sim::SimulatorOptions* o) { o->brightness_change_s = 1.5; });
  int changed = 0;
  for (int i = 0; i < s->num_frames(); ++i) changed += s->Truth(i).brightness_changed ? 1 : 0;
  EXPECT_GT(changed, 10);
  eval::Score full, gyro;
  for (eval::Method method : {eval::Method::kGyroOnly, eval::Method::kSteadiface}) {
    std::vector<StabilizerFrame> frames;
    (method == eval::Method::kSteadiface ? full : gyro) = ScoreMethod(*s, method, &frames);
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

// A legged robot's camera (640x480, 60 deg, 8 Hz vibration) and a person
// 2.75 m away: the face is 30 px wide, below dlib's 80 px window. The
// search finds it in an upsampled tile, the tracker fits its landmarks on
// an upsampled crop, and the stabilizer takes it over from gyro-only without
// a step: its head target starts where the smoothly moving virtual camera
// shows the face, not where this frame's shake puts it (before: an 8 px
// step at the acquisition, and the head 0.88x gyro-only's).
TEST(PipelinePresetTest, ARobotsDistantFaceIsFoundAndTakenOverWithoutAStep) {
  auto s = MakeSimulator("robot", [](sim::SimulatorOptions* o) { o->head.distance_m = 2.75; });
  EXPECT_NEAR(s->Truth(0).face_scale_px, 30.0, 1.0);
  eval::Score full, gyro;
  for (eval::Method method : {eval::Method::kGyroOnly, eval::Method::kSteadiface}) {
    std::vector<StabilizerFrame> frames;
    (method == eval::Method::kSteadiface ? full : gyro) = ScoreMethod(*s, method, &frames);
    if (method == eval::Method::kSteadiface) {
      int used = 0;
      for (const StabilizerFrame& f : frames) used += f.flags.face_used ? 1 : 0;
      EXPECT_GE(used, 0.9 * frames.size()) << "the 30 px face was not used";
    }
  }
  std::cout << "[ robot, 30 px face ] head jitter gyro-only " << gyro.head_jitter_px
            << " / steadiface " << full.head_jitter_px << " px; largest head step "
            << gyro.head_max_step_px << " / " << full.head_max_step_px << " px\n";
  EXPECT_LE(full.head_jitter_px, 0.6 * gyro.head_jitter_px);
  EXPECT_LE(full.head_max_step_px, gyro.head_max_step_px);
  EXPECT_EQ(full.undefined_fraction, 0.0);
}

// A camera without an IMU (rotation_source visual): the rotation comes from
// the video. On pan and walk the background stays within 3x of what the
// gyro gives (on walk well below the input's), and global mode holds the
// head within 1.3x of the gyro-driven head.
TEST(PipelinePresetTest, WithoutAnImuTheVideoGivesTheRotation) {
  for (const std::string preset : {"pan", "walk"}) {
    SCOPED_TRACE(preset);
    auto s = MakeSimulator(preset);
    eval::Score by[2][2];  // [visual][method: gyro-only, steadiface]
    for (int visual = 0; visual < 2; ++visual) {
      for (int k = 0; k < 2; ++k) {
        const eval::Method method = k == 0 ? eval::Method::kGyroOnly : eval::Method::kSteadiface;
        PipelineOptions po = eval::OptionsFor(*s, method);
        if (visual) po.rotation_source = RotationSource::kVisual;
        std::unique_ptr<eval::Scorecard> card;
        ASSERT_TRUE(eval::MakeScorecard(*s, po, &card).ok());
        ASSERT_TRUE(eval::RunMethod(*s, method, po, card.get()).ok());
        by[visual][k] = card->Compute();
      }
    }
    const PresetResult r = Score(preset);
    std::cout << "[ " << preset << ", rotation from the video ] visible background, gyro-only: "
              << by[1][0].visible_background_jitter_px << " px (gyro "
              << by[0][0].visible_background_jitter_px << ", input "
              << r.none.visible_background_jitter_px << "); head, global: "
              << by[1][1].head_jitter_px << " px (gyro " << by[0][1].head_jitter_px << ")\n";
    EXPECT_LE(by[1][0].visible_background_jitter_px, 3.0 * by[0][0].visible_background_jitter_px);
    // (On pan the gyro itself keeps most of the input's jitter: it follows
    // the pan.)
    if (preset == "walk") {
      EXPECT_LE(by[1][0].visible_background_jitter_px, 0.5 * r.none.visible_background_jitter_px);
    }
    EXPECT_LE(by[1][1].head_jitter_px, 1.3 * by[0][1].head_jitter_px);
    EXPECT_EQ(by[1][1].undefined_fraction, 0.0);
  }
}

// The rotation from the video starts on its second frame: the first has
// no turn across its rows (rolling shutter) until the next one, so it is
// withheld. Shown uncorrected, as before, the next frame jumped by the
// first's shutter skew: the layered visible background's largest step was
// 5.2 px on passer_by and 5.6 px on low_texture (seed 2, 640x360), against
// 1.2 px with the IMU. The bar: no step over 2 px.
TEST(PipelinePresetTest, TheVideosFirstFrameIsWithheldAndTheStartDoesNotJump) {
  for (const std::string preset : {"passer_by", "low_texture"}) {
    SCOPED_TRACE(preset);
    auto s = MakeSimulator(preset, [](sim::SimulatorOptions* o) { o->seed = 2; });
    PipelineOptions po = eval::OptionsFor(*s, eval::Method::kSteadifaceLayered);
    po.rotation_source = RotationSource::kVisual;
    std::unique_ptr<eval::Scorecard> card;
    ASSERT_TRUE(eval::MakeScorecard(*s, po, &card).ok());
    std::vector<StabilizerFrame> frames;
    eval::RunMethodOptions run;
    run.frames = &frames;
    ASSERT_TRUE(eval::RunMethod(*s, eval::Method::kSteadifaceLayered, po, card.get(), run).ok());
    EXPECT_EQ(frames.size() + 1, static_cast<size_t>(s->num_frames()));
    const eval::Score sc = card->Compute();
    std::cout << "[ " << preset << ", rotation from the video, layered ] largest step of the "
              << "visible background " << sc.visible_background_max_step_px << " px\n";
    EXPECT_LE(sc.visible_background_max_step_px, 2.0);
    EXPECT_EQ(sc.undefined_fraction, 0.0);
  }
}

// The withheld first frame is not drawn (its mesh is still computed, as
// the warp's state), in global and layered mode; the frames after it are.
TEST(PipelinePresetTest, TheVideosWithheldFirstFrameIsNotDrawn) {
  auto s = MakeSimulator("walk");
  for (const eval::Method method : {eval::Method::kSteadiface, eval::Method::kSteadifaceLayered}) {
    PipelineOptions po = eval::OptionsFor(*s, method);
    po.rotation_source = RotationSource::kVisual;
    po.render_output = true;
    std::unique_ptr<Pipeline> p;
    ASSERT_TRUE(Pipeline::Create(s->intrinsics(), po, &p).ok());
    for (int i = 0; i < 3; ++i) {
      SCOPED_TRACE(i);
      cv::Mat image;
      sim::SimTruth truth;
      ASSERT_TRUE(s->Render(i, &image, &truth).ok());
      PipelineFrame out;
      ASSERT_TRUE(p->ProcessFrame(image, s->Truth(i).stamp, nullptr, 0.0, &out).ok());
      EXPECT_EQ(out.withheld, i == 0);
      EXPECT_EQ(out.output.empty(), i == 0);
      EXPECT_GT(out.timings.mesh_ms, 0.0);
      if (i == 0) EXPECT_EQ(out.timings.remap_ms, 0.0);
    }
  }
}

// two_faces: a second face walks up to 0.4 m beside the subject, and the
// visible background is only the view's left quarter by the end. Its
// features fit each frame's turn, and were found again on it as soon as the
// scene trail dropped them: the layered visible background with the video
// was 1.77x the IMU's gyro-only on seed 1 (bar: 1.5x). Measured now: 1.1x.
TEST(PipelinePresetTest, ANearSecondFaceDoesNotTurnTheVideosRotation) {
  auto s = MakeSimulator("two_faces");
  eval::Score layered_video, gyro_imu;
  for (const eval::Method method : {eval::Method::kGyroOnly, eval::Method::kSteadifaceLayered}) {
    PipelineOptions po = eval::OptionsFor(*s, method);
    const bool video = method == eval::Method::kSteadifaceLayered;
    if (video) po.rotation_source = RotationSource::kVisual;
    std::unique_ptr<eval::Scorecard> card;
    ASSERT_TRUE(eval::MakeScorecard(*s, po, &card).ok());
    ASSERT_TRUE(eval::RunMethod(*s, method, po, card.get()).ok());
    (video ? layered_video : gyro_imu) = card->Compute();
  }
  std::cout << "[ two_faces ] visible background: layered with the video "
            << layered_video.visible_background_jitter_px << " px, gyro-only with the IMU "
            << gyro_imu.visible_background_jitter_px << " px\n";
  EXPECT_LE(layered_video.visible_background_jitter_px,
            1.5 * gyro_imu.visible_background_jitter_px);
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

eval::Score RunCrop(const sim::Simulator& s, eval::Method method, CropMode mode) {
  return testing_util::ScoreRun(s, method, [mode](PipelineOptions* o) { o->crop.mode = mode; });
}

// The dynamic crop (output/crop dynamic): on a camera at rest the view
// stays at its widest from the start; under the recorded running shake it
// closes to the fixed crop's margin, and no output pixel is ever undefined.
TEST(PipelinePresetTest, TheDynamicCropOpensOnACalmCameraAndClosesUnderShake) {
  auto still = MakeSimulator("still");
  const eval::Score calm = RunCrop(*still, eval::Method::kSteadiface, CropMode::kDynamic);
  EXPECT_GE(calm.kept_width_min, 0.93);
  EXPECT_EQ(calm.undefined_fraction, 0.0);
  auto run = MakeSimulator("run", [](sim::SimulatorOptions* o) { o->duration_s = 4.0; });
  const eval::Score fixed = RunCrop(*run, eval::Method::kGyroOnly, CropMode::kFixed);
  const eval::Score dynamic = RunCrop(*run, eval::Method::kGyroOnly, CropMode::kDynamic);
  std::cout << "[ dynamic crop ] still: kept " << calm.kept_width_mean << " (least "
            << calm.kept_width_min << "); run, gyro-only: kept " << dynamic.kept_width_mean
            << " (least " << dynamic.kept_width_min << "), background "
            << dynamic.visible_background_jitter_px << " px (fixed "
            << fixed.visible_background_jitter_px << "), largest step "
            << dynamic.kept_width_max_step << "\n";
  EXPECT_NEAR(fixed.kept_width_min, 0.7, 1e-12);  // 0.7 throughout
  EXPECT_NEAR(fixed.kept_width_mean, 0.7, 1e-12);
  EXPECT_LE(dynamic.kept_width_min, 0.72);
  EXPECT_GE(dynamic.kept_width_min, 0.7 - 1e-12);
  EXPECT_EQ(dynamic.undefined_fraction, 0.0);
  // A frame's zoom step stays within the tightening rate, 0.15/s x 2 sides.
  EXPECT_LE(dynamic.kept_width_max_step, 2 * 0.15 / 30 + 1e-9);
}

// The stabilized camera_info follows the crop: its focal length in output
// pixels is the fixed crop's times 0.7 / kept width, its centre stays.
TEST(PipelinePresetTest, TheOutputIntrinsicsFollowTheDynamicCrop) {
  auto s = MakeSimulator("walk");
  PipelineOptions po = eval::OptionsFor(*s, eval::Method::kGyroOnly);
  po.crop.mode = CropMode::kDynamic;
  std::unique_ptr<Pipeline> p;
  ASSERT_TRUE(Pipeline::Create(s->intrinsics(), po, &p).ok());
  OutputGeometry fixed;
  ASSERT_TRUE(OutputGeometry::Create(p->camera_model(), po.warp.output, &fixed).ok());
  const CameraIntrinsics k0 = fixed.VirtualIntrinsics(Eigen::Vector2d::Zero());
  const cv::Mat frame(s->intrinsics().height, s->intrinsics().width, CV_8UC1, cv::Scalar(0));
  size_t g = 0;
  double least = 1.0, most = 0.0;
  for (int i = 0; i < 60; ++i) {
    const Time stamp = s->Truth(i).stamp;
    eval::FeedGyroForFrame(*s, stamp, po.imu.imu_time_offset_s, p.get(), &g);
    PipelineFrame out;
    ASSERT_TRUE(p->ProcessFrame(frame, stamp, nullptr, 0.0, &out).ok());
    const double kept = 1.0 - 2.0 * out.crop.crop_ratio;
    least = std::min(least, kept);
    most = std::max(most, kept);
    EXPECT_NEAR(out.output_intrinsics.fx, k0.fx * 0.7 / kept, 1e-9 * k0.fx) << i;
    EXPECT_NEAR(out.output_intrinsics.fy, k0.fy * 0.7 / kept, 1e-9 * k0.fy) << i;
    EXPECT_EQ(out.output_intrinsics.width, k0.width);
    EXPECT_TRUE(out.crop.dynamic);
    EXPECT_GE(out.crop.shake_need, 0.0);
  }
  EXPECT_GT(most - least, 0.02) << "the crop should have moved on walk";
}

}  // namespace
}  // namespace steadiface

namespace steadiface {
namespace {

eval::Score RunHorizon(const sim::Simulator& s, HorizonMode mode, double level_tolerance_deg = 1.0) {
  PipelineOptions po = eval::OptionsFor(s, eval::Method::kGyroOnly);
  po.horizon.mode = mode;
  po.horizon.level_tolerance_deg = level_tolerance_deg;
  std::unique_ptr<eval::Scorecard> card;
  EXPECT_TRUE(eval::MakeScorecard(s, po, &card).ok());
  const Status st = eval::RunMethod(s, eval::Method::kGyroOnly, po, card.get());
  EXPECT_TRUE(st.ok()) << st.message();
  return card->Compute();
}

// The level horizon (output/horizon) against the simulator's true gravity:
// on a walk under a slow +-10 deg roll, lock holds the output within half a
// degree RMS and level within two; on a walk without roll, level leaves the
// visible background as steady as without it.
TEST(PipelinePresetTest, TheHorizonIsHeldLevelFromTheAccelerometer) {
  auto roll = MakeSimulator("roll");
  const eval::Score off = RunHorizon(*roll, HorizonMode::kOff);
  const eval::Score level = RunHorizon(*roll, HorizonMode::kLevel);
  const eval::Score lock = RunHorizon(*roll, HorizonMode::kLock);
  auto walk = MakeSimulator("walk");
  const eval::Score walk_off = RunHorizon(*walk, HorizonMode::kOff);
  const eval::Score walk_level = RunHorizon(*walk, HorizonMode::kLevel);
  std::cout << "[ horizon, gyro-only ] roll preset: output roll RMS off " << off.output_roll_rms_deg
            << " / level " << level.output_roll_rms_deg << " / lock " << lock.output_roll_rms_deg
            << " deg (input " << off.input_roll_rms_deg << "); walk, visible background off "
            << walk_off.visible_background_jitter_px << " / level "
            << walk_level.visible_background_jitter_px << " px\n";
  EXPECT_GT(off.output_roll_rms_deg, 4.0);  // gyro-only keeps the roll
  EXPECT_LE(level.output_roll_rms_deg, 2.0);
  EXPECT_LE(lock.output_roll_rms_deg, 0.5);
  EXPECT_EQ(lock.undefined_fraction, 0.0);
  EXPECT_LE(walk_level.visible_background_jitter_px, 1.1 * walk_off.visible_background_jitter_px);
}

// A nearly still camera: the gravity estimate's own error in its first
// seconds (a few tenths of a degree, from the hand's accelerations) is
// within level's 1 deg tolerance, so level leaves the view's roll as off
// does. Pulling every roll (tolerance 0) rolls the view after that error:
// 0.04 -> 0.06 deg RMS, its visible background 1.2x as jittery (seed 1).
TEST(PipelinePresetTest, LevelLeavesANearlyStillViewsRollAlone) {
  auto drift = MakeSimulator("drift");
  const eval::Score off = RunHorizon(*drift, HorizonMode::kOff);
  const eval::Score level = RunHorizon(*drift, HorizonMode::kLevel);
  const eval::Score pull_all = RunHorizon(*drift, HorizonMode::kLevel, 0.0);
  std::cout << "[ horizon, gyro-only ] drift: output roll RMS off " << off.output_roll_rms_deg
            << " / level " << level.output_roll_rms_deg << " / level without tolerance "
            << pull_all.output_roll_rms_deg << " deg; visible background "
            << off.visible_background_jitter_px << " / " << level.visible_background_jitter_px
            << " / " << pull_all.visible_background_jitter_px << " px\n";
  EXPECT_LE(level.output_roll_rms_deg, off.output_roll_rms_deg + 0.005);
  EXPECT_LE(level.visible_background_jitter_px, 1.02 * off.visible_background_jitter_px);
  EXPECT_GT(pull_all.output_roll_rms_deg, off.output_roll_rms_deg + 0.01);
  EXPECT_GT(pull_all.visible_background_jitter_px, 1.1 * off.visible_background_jitter_px);
}

}  // namespace
}  // namespace steadiface

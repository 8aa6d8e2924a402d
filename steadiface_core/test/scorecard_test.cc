// eval::Scorecard against closed forms on simulated sequences: a still
// scene, warps that cancel or add known motion, the pan, the parallax floor.
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <string>

#include <gtest/gtest.h>

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

// The still preset with a head that does not move either.
std::unique_ptr<sim::Simulator> StillHead() {
  return MakeSimulator("still", [](sim::SimulatorOptions* o) {
    o->head.bob_amplitude_m = o->head.sway_amplitude_m = o->head.jitter_rms_m = 0.0;
    o->head.yaw_amplitude_rad = o->head.pitch_amplitude_rad = o->head.lean_amplitude_m = 0.0;
  });
}

TEST(ScorecardTest, IdentityOnAStillSceneScoresZeroJitter) {
  auto s = StillHead();
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
  auto s = MakeSimulator("walk");
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
  auto s = StillHead();
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
  const double pan_only = input_background(*MakeSimulator("pan", [](sim::SimulatorOptions* o) {
    o->camera.shake_rms_rad = 0.0;
    o->camera.translation_rms_m = 0.0;
  }));
  const double preset = input_background(*MakeSimulator("pan"));
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
  auto s = MakeSimulator("still");
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

}  // namespace
}  // namespace steadiface

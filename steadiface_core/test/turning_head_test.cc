// The paper's pose rule on a head that turns like a head: the simulator's
// relief head turns about its skull, so its landmarks swing sideways by the
// turn as a real head's do (sim/head_relief.h). The pose-invariant centre
// takes the swing back; w_f fades as the yaw grows; the face's return is
// taken up without a jump. docs/evaluation.md, "A head that turns like a
// head", has the tables over seeds.
#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "score_util.h"
#include "sim_util.h"
#include "steadiface_core/eval/evaluation.h"
#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/eval/scorecard.h"
#include "steadiface_core/face/head_turn.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace {

using testing_util::MakeSimulator;

eval::Score RunWith(const sim::Simulator& s, eval::Method m, double pivot_depth,
                    std::vector<StabilizerFrame>* frames = nullptr, double follow_s = -1.0) {
  return testing_util::ScoreRun(
      s, m,
      [=](PipelineOptions* o) {
        if (pivot_depth >= 0.0) o->stabilizer.dynamic.pose_pivot_depth = pivot_depth;
        if (follow_s >= 0.0) o->face.follow_turned_s = follow_s;
      },
      frames);
}

// Runs the pipeline with `po` over every frame of `s`, handing each frame's
// output and truth to `each`.
void ForEachFrame(
    const sim::Simulator& s, const PipelineOptions& po,
    const std::function<void(int, const PipelineFrame&, const sim::SimTruth&)>& each) {
  std::unique_ptr<Pipeline> p;
  ASSERT_TRUE(Pipeline::Create(s.intrinsics(), po, &p).ok());
  size_t g = 0;
  cv::Mat frame;
  sim::SimTruth truth;
  for (int i = 0; i < s.num_frames(); ++i) {
    eval::FeedGyroForFrame(s, s.Truth(i).stamp, po.imu.imu_time_offset_s, p.get(), &g);
    ASSERT_TRUE(s.Render(i, &frame, &truth).ok());
    PipelineFrame out;
    ASSERT_TRUE(p->ProcessFrame(frame, truth.stamp, nullptr, 0.0, &out).ok());
    each(i, out, truth);
  }
}

// A followed head's axis, the pose-invariant centre, in the image [px]:
// the located centre moved back by the pivot's swing.
double FollowedAxisX(const PipelineOptions& po, const FaceInfo& face) {
  return face.centre_px.x() +
         po.stabilizer.dynamic.pose_pivot_depth * face.scale_px * std::sin(face.yaw);
}

// drift: a standing person whose head drifts and turns (yaw 12 deg RMS).
// Following the landmarks' centre follows the turn (the paper's centre,
// pivot depth 0); the pose-invariant centre holds the head.
TEST(TurningHeadTest, ThePoseInvariantCentreHoldsATurningHead) {
  const auto s = MakeSimulator("drift");
  ASSERT_EQ(s->options().head_model, "relief");
  const eval::Score gyro = RunWith(*s, eval::Method::kGyroOnly, -1.0);
  const eval::Score paper = RunWith(*s, eval::Method::kSteadiface, 0.0);
  const eval::Score ours = RunWith(*s, eval::Method::kSteadiface, -1.0);
  std::cout << "[ drift, relief head ] head px: gyro-only "
            << gyro.head_jitter_px << ", landmark centre "
            << paper.head_jitter_px << ", pose-invariant centre "
            << ours.head_jitter_px << "\n";
  // Measured (seed 1): 6.93, 8.01, 2.29 px (2.50 with a plain low-pass on
  // the yaw).
  EXPECT_GT(paper.head_jitter_px, gyro.head_jitter_px);
  EXPECT_LE(ours.head_jitter_px, 0.5 * paper.head_jitter_px);
  EXPECT_LE(ours.head_jitter_px, 0.5 * gyro.head_jitter_px);
}

// turn_away: the landmarks are given up at about 38 deg of yaw, and the
// head is followed on as a turning cylinder (face/head_turn.h) until they
// return: the face is located on every frame, no frontal face is ever
// followed, and the output head is steadier than without following and
// than gyro-only's.
TEST(TurningHeadTest, AHeadTurnedPastTheLandmarksIsFollowed) {
  const auto s = MakeSimulator("turn_away");
  const PipelineOptions po = eval::OptionsFor(*s, eval::Method::kSteadiface);
  int located = 0, followed = 0, followed_frontal = 0;
  double worst_axis = 0.0;
  ForEachFrame(*s, po, [&](int i, const PipelineFrame& out, const sim::SimTruth& truth) {
    located += out.face.located() ? 1 : 0;
    if (!out.face.followed) return;
    ++followed;
    if (std::abs(truth.yaw) < 0.4) ++followed_frontal;
    // The followed head's axis (the pose-invariant centre) against the
    // truth's, while turning away (the yaw still growing).
    const double axis = FollowedAxisX(po, out.face);
    if (i < s->num_frames() / 2) {
      worst_axis = std::max(worst_axis, std::abs(axis - truth.head_px.x()));
    }
  });
  const eval::Score gyro = RunWith(*s, eval::Method::kGyroOnly, -1.0);
  const eval::Score held = RunWith(*s, eval::Method::kSteadiface, -1.0, nullptr, 0.0);
  const eval::Score ours = RunWith(*s, eval::Method::kSteadiface, -1.0);
  std::cout << "[ turn_away, relief head ] located on " << located << " of " << s->num_frames()
            << " frames, followed on " << followed << " (" << followed_frontal
            << " within 0.4 rad of frontal); the axis within " << worst_axis
            << " px of the true head centre while turning away; head px: gyro-only "
            << gyro.head_jitter_px << ", not followed " << held.head_jitter_px
            << ", followed " << ours.head_jitter_px << "\n";
  // Measured (seed 1): 90 of 90, followed on 58, 0 frontal; the axis
  // within 10.3 px (the pivot's model: 1.5 face scales against the
  // relief's 0.09 m); 7.25, 6.66, 4.11 px.
  EXPECT_EQ(located, s->num_frames());
  EXPECT_GT(followed, 40);
  EXPECT_EQ(followed_frontal, 0);
  EXPECT_LT(worst_axis, 16.0);
  EXPECT_LT(ours.head_jitter_px, 0.85 * held.head_jitter_px);
  EXPECT_LT(ours.head_jitter_px, 0.8 * gyro.head_jitter_px);
  EXPECT_EQ(ours.undefined_fraction, 0.0);
}

// turn_away with twice the head's 2-8 Hz jitter (3 mm RMS): the head's own
// motion changes by more than the face scale's share (0.15) from frame to
// frame, so a gate of that share alone ends every follow on its first
// frame; the gate widened by the jitter measured on the fitted frames
// (face/follow_speed_change_noise) follows the head through the turn.
TEST(TurningHeadTest, AJitteringHeadIsFollowedThroughItsTurn) {
  const auto s = MakeSimulator("turn_away", [](sim::SimulatorOptions* o) {
    o->head.jitter_rms_m *= 2.0;
  });
  // The head jitter and the frames the tracker followed, with the gate's
  // noise term at `noise`.
  auto run = [&s](double noise, int* followed) {
    const auto tweak = [=](PipelineOptions* o) { o->face.follow_speed_change_noise = noise; };
    PipelineOptions po = eval::OptionsFor(*s, eval::Method::kSteadiface);
    tweak(&po);
    *followed = 0;
    ForEachFrame(*s, po, [followed](int, const PipelineFrame& out, const sim::SimTruth&) {
      *followed += out.face.followed ? 1 : 0;
    });
    return testing_util::ScoreRun(*s, eval::Method::kSteadiface, tweak);
  };
  int followed_scale_only = 0, followed = 0;
  const eval::Score gyro = RunWith(*s, eval::Method::kGyroOnly, -1.0);
  const eval::Score scale_only = run(0.0, &followed_scale_only);
  const eval::Score ours = run(PipelineOptions().face.follow_speed_change_noise, &followed);
  std::cout << "[ turn_away, head jitter x2 ] followed on " << followed_scale_only << " / "
            << followed << " frames (gate: the face scale's share / widened by the jitter); head "
            << "px: gyro-only " << gyro.head_jitter_px << ", " << scale_only.head_jitter_px
            << " / " << ours.head_jitter_px << "\n";
  // Measured (seed 1): followed on 0 / 63 of 90 frames; 9.66, 8.82 / 6.85 px.
  EXPECT_LT(followed_scale_only, 10);
  EXPECT_GT(followed, 40);
  EXPECT_LT(ours.head_jitter_px, 0.8 * scale_only.head_jitter_px);
  EXPECT_LT(ours.head_jitter_px, 0.8 * gyro.head_jitter_px);
}

// turn_away with 1.3x the head's motion: the head turns to 90 deg of yaw and
// back. The cylinder's yaw reaches its limit (kHeadTurnMaxYaw) near the
// profile, where the flow no longer tells the turn from the axis' motion:
// followed on, the turn back was measured two to three times too fast and
// the axis drifted by 50 px, and global mode's head was 1.2x gyro-only's.
// The follow ends there and the head is held until the landmarks fit.
TEST(TurningHeadTest, AHeadTurnedToItsProfileIsHeldNotFollowedBack) {
  const auto s = MakeSimulator("turn_away", [](sim::SimulatorOptions* o) {
    ASSERT_TRUE(eval::ScaleHeadMotion(1.3, NAN, &o->head).ok());
  });
  const PipelineOptions po = eval::OptionsFor(*s, eval::Method::kSteadiface);
  int followed = 0, followed_after_profile = 0;
  bool profile = false;
  double worst_axis = 0.0;
  ForEachFrame(*s, po, [&](int, const PipelineFrame& out, const sim::SimTruth& truth) {
    if (out.face.valid) profile = false;  // fitted again
    if (!out.face.followed) return;
    ++followed;
    followed_after_profile += profile ? 1 : 0;
    if (std::abs(out.face.yaw) >= kHeadTurnMaxYaw) profile = true;
    const double axis = FollowedAxisX(po, out.face);
    worst_axis = std::max(worst_axis, std::abs(axis - truth.head_px.x()));
  });
  const eval::Score gyro = RunWith(*s, eval::Method::kGyroOnly, -1.0);
  const eval::Score held = RunWith(*s, eval::Method::kSteadiface, -1.0, nullptr, 0.0);
  const eval::Score ours = RunWith(*s, eval::Method::kSteadiface, -1.0);
  std::cout << "[ turn_away, head motion x1.3 ] followed on " << followed << " frames, "
            << followed_after_profile << " after its profile; the axis within " << worst_axis
            << " px of the true head centre; head px: gyro-only " << gyro.head_jitter_px
            << ", not followed " << held.head_jitter_px << ", followed " << ours.head_jitter_px
            << "\n";
  // Measured (seed 1): followed on 21 frames, 0 after the profile; the
  // axis within 14.1 px; 8.31, 8.43, 6.81 px. Followed back from the
  // profile: 10.30 px (before the yaw's one-euro filter).
  EXPECT_GT(followed, 10);
  EXPECT_EQ(followed_after_profile, 0);
  EXPECT_LT(worst_axis, 25.0);
  EXPECT_LT(ours.head_jitter_px, gyro.head_jitter_px);
  EXPECT_LT(ours.head_jitter_px, held.head_jitter_px);
  EXPECT_EQ(ours.undefined_fraction, 0.0);
}

// turn_away: the head turns 69 deg away and back. As it turns w_f fades
// (the pose rule: its target falls from 0.35 rad of yaw; PnP reads about
// 0.88 of the true yaw), and the face is taken up again as it turns back,
// without a jump: the output head's largest second difference is within
// 2x gyro-only's.
TEST(TurningHeadTest, ATurnFadesTheFaceAndItsReturnDoesNotJump) {
  const auto s = MakeSimulator("turn_away");
  std::vector<StabilizerFrame> frames;
  const eval::Score gyro = RunWith(*s, eval::Method::kGyroOnly, -1.0);
  const eval::Score ours =
      RunWith(*s, eval::Method::kSteadiface, -1.0, &frames);
  ASSERT_EQ(static_cast<int>(frames.size()), s->num_frames());
  double fit_turned = 0.0, fit_facing = 1.0, pose_turned = 0.0;
  int used_at_end = 0;
  for (int i = 0; i < s->num_frames(); ++i) {
    const double yaw = std::abs(s->Truth(i).yaw);
    // The pose rule's target while the turned face is used (fitted, or
    // followed: the followed yaw feeds the same rule), and w_f itself (it
    // fades with a time constant) once the turn is large.
    if (yaw > 0.8 && frames[i].flags.face_used) {
      pose_turned = std::max(pose_turned, frames[i].factors.pose_target);
    }
    if (yaw > 1.0) fit_turned = std::max(fit_turned, frames[i].factors.fit);
    if (yaw < 0.1 && i < 5)
      fit_facing = std::min(fit_facing, frames[i].factors.fit);
    if (i >= s->num_frames() - 10)
      used_at_end += frames[i].flags.face_used ? 1 : 0;
  }
  std::cout << "[ turn_away, relief head ] head px: gyro-only "
            << gyro.head_jitter_px << ", global " << ours.head_jitter_px
            << "; w_f factor facing " << fit_facing << ", turned beyond 1 rad "
            << fit_turned << ", pose target beyond 0.8 rad " << pose_turned
            << "; face used on " << used_at_end
            << " of the last 10 frames; head max "
            << "2nd difference " << ours.head_max_accel_px << " (gyro-only "
            << gyro.head_max_accel_px << ")\n";
  EXPECT_GT(fit_facing, 0.9);
  // Measured (seed 1): the target 0.1 (its floor) beyond 0.8 rad, w_f at most
  // 0.24 of its full weight beyond 1 rad (0.17 before the head was
  // followed: it was then lost).
  EXPECT_GT(pose_turned, 0.0);
  EXPECT_LT(pose_turned, 0.3);
  EXPECT_LT(fit_turned, 0.25);
  EXPECT_EQ(used_at_end, 10);  // the face turning back is recognised again
  EXPECT_LE(ours.head_max_accel_px, 2.0 * gyro.head_max_accel_px);
  EXPECT_EQ(ours.undefined_fraction, 0.0);
}

// A head whipping round to +-57 deg at 0.33 Hz (turn_away with the yaw and
// the turn speed of a head shaking "no" hard). On the second turn PnP's yaw
// lags the head (0.25 rad read at a true 0.39) while the whole face's
// appearance fades (0.88 -> 0.45 over six fits, every region intact); the
// landmarks are given up below follow_min_yaw. Followed as a covered face,
// by its translation with no yaw, the turn's swing of the face centre
// (40 px) was held as the head's motion: global mode at 3.1x gyro-only's.
// A face whose last fit had already faded is held instead.
TEST(TurningHeadTest, AHeadWhippingRoundIsHeldNotFollowedAsCovered) {
  const auto s = MakeSimulator("turn_away", [](sim::SimulatorOptions* o) {
    ASSERT_TRUE(eval::SetHeadTurn(1.0, 2.0, &o->head).ok());
  });
  const auto with_min_appearance = [&s](double a) {
    return testing_util::ScoreRun(*s, eval::Method::kSteadiface, [=](PipelineOptions* o) {
      o->face.follow_covered_min_appearance = a;
    });
  };
  const eval::Score gyro = RunWith(*s, eval::Method::kGyroOnly, -1.0);
  const eval::Score any_loss = with_min_appearance(0.0);
  const eval::Score ours = with_min_appearance(PipelineOptions().face.follow_covered_min_appearance);
  std::cout << "[ turn_away, +-57 deg at 0.33 Hz ] head px: gyro-only " << gyro.head_jitter_px
            << ", every loss followed as covered " << any_loss.head_jitter_px
            << ", a faded face held " << ours.head_jitter_px << "\n";
  // Measured (seed 1): 7.25, 15.85, 8.41 px (22.93 every loss followed as
  // covered while a covered face's yaw was reported as 0, not held).
  EXPECT_GT(any_loss.head_jitter_px, 2.0 * gyro.head_jitter_px);
  EXPECT_LT(ours.head_jitter_px, 1.25 * gyro.head_jitter_px);
  EXPECT_LT(ours.head_jitter_px, 0.6 * any_loss.head_jitter_px);
  EXPECT_EQ(ours.undefined_fraction, 0.0);
  // Out of range is refused.
  PipelineOptions bad;
  bad.face.follow_covered_min_appearance = 1.5;
  EXPECT_FALSE(ValidateFaceTrackerOptions(bad.face).ok());
}

// occlusion with three times the head's motion: the head turns by up to
// 0.3 rad as the hand covers it. A covered face is followed by its visible
// parts' translation, which does not show its turn; its pose is held at
// the last fits' (their median: the last one is already dragged by the
// hand). Reported as 0 instead, the pose-invariant centre swung by the
// pivot's whole offset (1.5 face scales times sin(yaw), 21 px here)
// on the first covered frame, and the output's head jumped with it.
TEST(TurningHeadTest, ACoveredHeadKeepsItsTurnWhileFollowed) {
  const auto s = MakeSimulator("occlusion", [](sim::SimulatorOptions* o) {
    ASSERT_TRUE(eval::ScaleHeadMotion(3.0, 1.0, &o->head).ok());
  });
  const PipelineOptions po = eval::OptionsFor(*s, eval::Method::kSteadiface);
  // The axis against the true head centre: its offset on the fitted frames
  // (the pivot's model), and the largest departure from it while followed.
  double offset = 0.0, worst = 0.0;
  int fitted = 0, followed = 0;
  std::vector<double> followed_error;
  ForEachFrame(*s, po, [&](int, const PipelineFrame& out, const sim::SimTruth& truth) {
    if (!out.face.located()) return;
    const double e = FollowedAxisX(po, out.face) - truth.head_px.x();
    if (out.face.valid) {
      offset += e;
      ++fitted;
    } else {
      followed_error.push_back(e);
    }
  });
  ASSERT_GT(fitted, 0);
  offset /= fitted;
  for (double e : followed_error) worst = std::max(worst, std::abs(e - offset));
  followed = static_cast<int>(followed_error.size());
  const eval::Score gyro = RunWith(*s, eval::Method::kGyroOnly, -1.0);
  const eval::Score ours = RunWith(*s, eval::Method::kSteadiface, -1.0);
  std::cout << "[ occlusion, head motion x3 ] " << followed << " frames followed, their axis within "
            << worst << " px of the fitted frames' offset (" << offset << " px); head px: gyro-only "
            << gyro.head_jitter_px << ", global " << ours.head_jitter_px << "\n";
  // Measured (seed 1): 2 frames followed, within 1.3 px of the offset
  // (-3.9 px); 15.75, 6.02 px. With the turn reported as 0 (the build
  // before): 20.9 px; 9.29 px.
  EXPECT_GT(followed, 0);
  EXPECT_LT(worst, 6.0);
  EXPECT_LT(ours.head_jitter_px, 0.45 * gyro.head_jitter_px);
}

// occlusion with twice the head's motion: the last fit before the hand
// covers the face has its regions disagreeing (the lowest at 0.59) and is
// dragged into a yaw spike (PnP 0.14 -> 0.30 rad in one frame). Taken at
// its word, that yaw marked the head as turned, the follow took it as a
// turning cylinder whose face swung 0.41 rad on its first frame, and the
// output's head left by 39 px over four frames. Such a fit's turn counts
// with the median of the last three (kDraggedYawJump): the face is
// followed as covered, its pose held.
TEST(TurningHeadTest, AFitDraggedByAHandDoesNotMarkTheHeadAsTurned) {
  const auto s = MakeSimulator("occlusion", [](sim::SimulatorOptions* o) {
    ASSERT_TRUE(eval::ScaleHeadMotion(2.0, 1.0, &o->head).ok());
  });
  const PipelineOptions po = eval::OptionsFor(*s, eval::Method::kSteadiface);
  int followed = 0;
  double largest_followed_yaw = 0.0;
  ForEachFrame(*s, po, [&](int, const PipelineFrame& out, const sim::SimTruth&) {
    if (!out.face.followed) return;
    ++followed;
    largest_followed_yaw = std::max(largest_followed_yaw, std::abs(out.face.yaw));
  });
  const eval::Score gyro = RunWith(*s, eval::Method::kGyroOnly, -1.0);
  const eval::Score ours = RunWith(*s, eval::Method::kSteadiface, -1.0);
  std::cout << "[ occlusion, head motion x2 ] " << followed << " frames followed, largest yaw "
            << largest_followed_yaw << " rad; head px: gyro-only " << gyro.head_jitter_px
            << ", global " << ours.head_jitter_px << "; largest step " << gyro.head_max_step_px
            << ", " << ours.head_max_step_px << "\n";
  // Measured (seed 1): 1 frame followed, yaw 0.15 rad; head 11.24, 4.16 px;
  // largest step 11.8, 7.9 px. The build before: 2 frames followed as
  // turned (yaw 0.41); head 7.85 px, largest step 17.2 px.
  EXPECT_GT(followed, 0);
  EXPECT_LT(largest_followed_yaw, 0.25);
  EXPECT_LT(ours.head_jitter_px, 0.5 * gyro.head_jitter_px);
  EXPECT_LT(ours.head_max_step_px, gyro.head_max_step_px);
}

// turn_away at 1280x720, seed 3: 57 deg into the turn, with the head
// followed as a turning cylinder within 3 px of the truth, the landmark
// model fits the turned face and PnP reads 21 deg. Accepted, that fit put
// the head's axis 105 px off, the follow went on from it, and global
// mode's head was 3.6x gyro-only's (a 95 px step when the next true fit
// came). A fit whose yaw disagrees with the followed head's by more than
// 0.4 rad is turned away (at most three in a row), and the follow goes on.
TEST(TurningHeadTest, AFitOfAFaceStillTurnedPastTheLandmarksDoesNotEndTheFollow) {
  const auto s = MakeSimulator("turn_away", [](sim::SimulatorOptions* o) {
    o->width = 1280;
    o->height = 720;
    o->seed = 3;
  });
  const PipelineOptions po = eval::OptionsFor(*s, eval::Method::kSteadiface);
  int turned_away = 0;
  double worst_turned = 0.0;  // the axis' error while the head is turned past 0.9 rad
  ForEachFrame(*s, po, [&](int, const PipelineFrame& out, const sim::SimTruth& truth) {
    turned_away += out.face.failure == FaceFailure::kTurnMismatch ? 1 : 0;
    if (out.face.located() && std::abs(truth.yaw) > 0.9) {
      worst_turned =
          std::max(worst_turned, std::abs(FollowedAxisX(po, out.face) - truth.head_px.x()));
    }
  });
  const eval::Score gyro = RunWith(*s, eval::Method::kGyroOnly, -1.0);
  const eval::Score ours = RunWith(*s, eval::Method::kSteadiface, -1.0);
  std::cout << "[ turn_away 1280x720, seed 3 ] " << turned_away
            << " fits turned away; the axis within " << worst_turned
            << " px of the true head beyond 0.9 rad; head px: gyro-only " << gyro.head_jitter_px
            << ", global " << ours.head_jitter_px << "\n";
  // Measured: 1 fit turned away; within 28.8 px (the cylinder's own error
  // at 1.2 rad, as before); 15.30, 13.78 px. Before: 105 px; 55.09 px.
  EXPECT_GT(turned_away, 0);
  EXPECT_LT(worst_turned, 40.0);
  EXPECT_LT(ours.head_jitter_px, gyro.head_jitter_px);
}

}  // namespace
}  // namespace steadiface

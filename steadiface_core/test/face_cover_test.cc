// The face tracker with something in front of the face: a solid block, a
// flat hand sweeping across it, a textured cover (face/face_tracker.h:
// the region check, the covered face's follow and its gate).
#include <algorithm>
#include <iostream>

#include <gtest/gtest.h>

#include "rendered_face.h"
#include "test_util.h"

namespace steadiface {
namespace {

using testing_util::At;
using testing_util::LoadImage;
using testing_util::ModelFor;
using testing_util::Occluder;
using testing_util::RenderMovingFace;
using testing_util::Rendered;
using testing_util::ShakyTimeline;
using testing_util::Tracker;

TEST(FaceTrackerTest, OcclusionGivesLostNotConfidentGarbage) {
  const CameraModel m = ModelFor(640, 360);
  const OrientationTimeline tl = ShakyTimeline();
  const RowTiming timing(RollingShutterOptions(), 360);
  const int n = 20, occlude_at = 8;
  Occluder block;
  block.from = occlude_at;
  const Rendered seq = RenderMovingFace(m, tl, timing, n, 30.0, block);
  auto t = Tracker(m);
  int first_lost = -1;
  for (int i = 0; i < n; ++i) {
    FaceInfo fi;
    ASSERT_TRUE(t->Process(seq.frames[i], At(0.1 + i / 30.0), &tl, &timing, &fi).ok());
    if (i < occlude_at) {
      EXPECT_TRUE(fi.valid) << i;
    } else {
      // Covered by a solid block: never a valid face.
      EXPECT_FALSE(fi.valid) << "frame " << i << " conf " << fi.confidence;
      EXPECT_EQ(fi.confidence, 0.0);
      if (first_lost < 0 && fi.state == TrackingState::kLost) first_lost = i;
      EXPECT_NE(fi.failure, FaceFailure::kNone);
    }
  }
  std::cout << "[ occlusion ] lost at frame " << first_lost << " (occluded from "
            << occlude_at << ")\n";
  ASSERT_GE(first_lost, occlude_at);
  EXPECT_LE(first_lost - occlude_at, 2);
}

// A hand (a flat 8 x 30 cm block) sweeps across the face from right to
// left. While it covers part of the face the landmarks would follow it; the
// per-region check (eyes, nose, mouth) rejects those frames instead, so no
// accepted centre is 5 px off the truth (3.5 px where the hand first
// touches the face's edge, every region still above 0.5). Without the check
// (min_region_appearance -1) the same sequence accepts centres 24 px off:
// the check is what keeps the hand out. The rejected frames are followed
// by the face's parts the hand leaves in view (follow_covered_s) as long as
// they can be tracked, each within 4 px of the truth; the frames where the
// hand hides nearly all of the face are held.
struct HandRun {
  int occluded = 0, followed = 0, held = 0;
  double worst_fitted = 0.0, worst_followed = 0.0;
};

HandRun RunHand(const CameraModel& m, const OrientationTimeline& tl, const RowTiming& timing,
                const Rendered& seq, const FaceTrackerOptions& o) {
  auto t = Tracker(m, o);
  HandRun r;
  for (size_t i = 0; i < seq.frames.size(); ++i) {
    FaceInfo fi;
    EXPECT_TRUE(t->Process(seq.frames[i], At(0.1 + i / 30.0), &tl, &timing, &fi).ok());
    if (i < 10) EXPECT_TRUE(fi.valid) << i;  // before the hand reaches the face
    r.occluded += fi.failure == FaceFailure::kOccluded;
    r.followed += fi.followed ? 1 : 0;
    r.held += fi.located() ? 0 : 1;
    const double e = fi.located() ? (fi.centre_px - seq.truth_centre[i]).norm() : 0.0;
    double& worst = fi.valid ? r.worst_fitted : r.worst_followed;
    worst = std::max(worst, e);
  }
  return r;
}

Occluder SweepingHand(double width_m) {
  Occluder hand;
  hand.from = 0;
  hand.width_m = width_m;
  // From 0.3 m right of the face to 0.3 m left over frames 10-50.
  hand.dx = [](double t) {
    const double s = std::min(1.0, std::max(0.0, (t - 0.1 - 10 / 30.0) / (40 / 30.0)));
    return 0.3 - 0.6 * s;
  };
  return hand;
}

TEST(FaceTrackerTest, AHandOverPartOfTheFaceIsFollowedByWhatItLeavesInView) {
  const CameraModel m = ModelFor(640, 360);
  const OrientationTimeline tl = ShakyTimeline();
  const RowTiming timing(RollingShutterOptions(), 360);
  const Rendered seq = RenderMovingFace(m, tl, timing, 60, 30.0, SweepingHand(0.08));
  FaceTrackerOptions o;
  const HandRun on = RunHand(m, tl, timing, seq, o);
  o.follow_covered_s = 0.0;
  const HandRun held = RunHand(m, tl, timing, seq, o);
  o.min_region_appearance = -1.0;
  // Without the check, the hand drags the landmarks so far that PnP reads
  // a turn (0.53 rad), and the face would then be followed as turned
  // (follow_turned_s): off, so the comparison is the check's alone.
  o.follow_turned_s = 0.0;
  const HandRun unchecked = RunHand(m, tl, timing, seq, o);
  std::cout << "[ hand ] region check on: " << on.occluded << " frames rejected as occluded, "
            << on.followed << " followed (worst " << on.worst_followed << " px), " << on.held
            << " held, worst accepted centre " << on.worst_fitted << " px; without the follow "
            << held.held << " held; without the check: worst " << unchecked.worst_fitted
            << " px\n";
  EXPECT_GT(on.occluded, 0);
  EXPECT_EQ(unchecked.occluded, 0);
  EXPECT_LT(on.worst_fitted, 5.0);
  EXPECT_GT(unchecked.worst_fitted, 10.0);
  // Measured: 4 of the rejected frames followed, 3.5 px off (the last
  // fit's own error, carried), 5 held against 9 without the follow.
  EXPECT_EQ(held.followed, 0);
  EXPECT_GE(on.followed, 3);
  EXPECT_LT(on.worst_followed, 4.0);
  EXPECT_LE(on.held, held.held - 3);
}

// A textured cover (a patch of a street photo, 12 cm wide) sweeps across the
// face faster than the head moves: its own corners are tracked too, and
// wherever they outnumber the face's, their median moves with the cover,
// not on as the head did (follow_max_speed_change); those frames are held.
// No followed centre moves away from the last fit's.
TEST(FaceTrackerTest, ATexturedCoverIsNeverFollowed) {
  const CameraModel m = ModelFor(640, 360);
  const OrientationTimeline tl = ShakyTimeline();
  const RowTiming timing(RollingShutterOptions(), 360);
  Occluder cover = SweepingHand(0.12);
  cover.texture = LoadImage("leuvenA.jpg");
  const Rendered seq = RenderMovingFace(m, tl, timing, 60, 30.0, cover);
  const HandRun r = RunHand(m, tl, timing, seq, FaceTrackerOptions());
  std::cout << "[ textured cover ] " << r.followed << " frames followed (worst " << r.worst_followed
            << " px), " << r.held << " held, worst accepted centre " << r.worst_fitted << " px\n";
  // Measured: 3 frames followed, worst 4.85 px against the last fit's 4.4
  // (the cover had begun to drag it; the follow's first frame shows no
  // turn, so it turns on at the last fits' rate, clipped to
  // kHeadTurnMaxRate), then 9 held until the face is fitted again. With
  // the gate on covered faces only, the landmarks the cover dragged read
  // as a turn, the turned follow took the cover's tracks and ran 258 px
  // off the face.
  EXPECT_GT(r.held, 0);
  EXPECT_LT(r.worst_fitted, 5.0);
  EXPECT_LT(r.worst_followed, r.worst_fitted + 0.5);
}

}  // namespace
}  // namespace steadiface

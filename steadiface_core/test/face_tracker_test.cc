#include "steadiface_core/face/face_tracker.h"

#include <cmath>
#include <iostream>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/common/so3.h"
#include "steadiface_core/face/generic_face.h"
#include "steadiface_core/face/head_pose.h"
#include "steadiface_core/sim/scene_renderer.h"
#include "test_util.h"

namespace steadiface {
namespace {

using testing_util::At;
using testing_util::LoadImage;

CameraModel ModelFor(int w, int h, double hfov = 1.0) {
  CameraModel m;
  EXPECT_TRUE(CameraModel::Create(IntrinsicsFromHorizontalFov(w, h, hfov),
                                  CameraModelOptions(), &m)
                  .ok());
  return m;
}

std::unique_ptr<FaceTracker> Tracker(const CameraModel& m,
                                     FaceTrackerOptions o = FaceTrackerOptions()) {
  std::unique_ptr<FaceTracker> t;
  const Status s = FaceTracker::Create(m, o, &t);
  EXPECT_TRUE(s.ok()) << s.message();
  return t;
}

Eigen::Vector2d Apply(const cv::Matx33d& H, const Eigen::Vector2d& p) {
  const cv::Vec3d q = H * cv::Vec3d(p.x(), p.y(), 1.0);
  return Eigen::Vector2d(q[0] / q[2], q[1] / q[2]);
}

TEST(FaceTrackerTest, FindsTheFaceAnd68LandmarksInARealPhoto) {
  const cv::Mat img = LoadImage("astronaut.png");
  ASSERT_FALSE(img.empty());
  const CameraModel m = ModelFor(img.cols, img.rows);
  auto t = Tracker(m);
  FaceInfo fi;
  ASSERT_TRUE(t->Process(img, At(1.0), nullptr, nullptr, &fi).ok());
  EXPECT_TRUE(fi.valid);
  EXPECT_EQ(fi.state, TrackingState::kTracking);
  EXPECT_TRUE(fi.detected);
  ASSERT_EQ(fi.landmarks_px.size(), 68u);
  ASSERT_EQ(fi.landmarks_normalized.size(), 68u);
  // The face in this portrait: eyes above the nose above the mouth, inside
  // the upper middle of the frame.
  EXPECT_LT(fi.landmarks_px[36].y(), fi.landmarks_px[30].y());
  EXPECT_LT(fi.landmarks_px[30].y(), fi.landmarks_px[57].y());
  EXPECT_GT(fi.centre_px.x(), 150);
  EXPECT_LT(fi.centre_px.x(), 300);
  EXPECT_GT(fi.centre_px.y(), 60);
  EXPECT_LT(fi.centre_px.y(), 200);
  EXPECT_GT(fi.confidence, 0.8);
  // Normalized coordinates agree with the camera model.
  const Eigen::Vector2d n = m.PixelToNormalized(fi.landmarks_px[30]);
  EXPECT_NEAR((n - fi.landmarks_normalized[30]).norm(), 0.0, 1e-12);
  // A frontal portrait: small head pose.
  ASSERT_TRUE(fi.has_pose);
  EXPECT_LT(std::abs(fi.yaw), 0.2);
  EXPECT_LT(std::abs(fi.pitch), 0.25);
  EXPECT_LT(std::abs(fi.roll), 0.15);
  // The observation the stabilizer gets.
  const FaceObservation o = fi.ToObservation();
  EXPECT_TRUE(o.valid);
  EXPECT_EQ(o.landmarks.size(), 68u);
  EXPECT_EQ(o.landmark_rows.size(), 68u);
}

TEST(FaceTrackerTest, LandmarksAreEquivariantUnderKnownWarps) {
  const cv::Mat img = LoadImage("astronaut.png");
  const CameraModel m = ModelFor(img.cols, img.rows);
  auto t = Tracker(m);
  FaceInfo ref;
  ASSERT_TRUE(t->Process(img, At(1.0), nullptr, nullptr, &ref).ok());
  ASSERT_TRUE(ref.valid);
  const cv::Point2f c(static_cast<float>(ref.centre_px.x()),
                      static_cast<float>(ref.centre_px.y()));
  struct Case {
    const char* name;
    cv::Matx33d H;
  };
  std::vector<Case> cases;
  auto similarity = [&](double angle_deg, double scale, double tx, double ty) {
    const cv::Mat A = cv::getRotationMatrix2D(c, angle_deg, scale);
    cv::Matx33d H(A.at<double>(0, 0), A.at<double>(0, 1), A.at<double>(0, 2) + tx,
                  A.at<double>(1, 0), A.at<double>(1, 1), A.at<double>(1, 2) + ty, 0, 0, 1);
    return H;
  };
  cases.push_back({"shift", similarity(0, 1.0, 23.0, -17.0)});
  cases.push_back({"rotate +15", similarity(15, 1.0, 0, 0)});
  cases.push_back({"rotate -15", similarity(-15, 1.0, 0, 0)});
  cases.push_back({"scale 0.7", similarity(0, 0.7, 0, 0)});
  cases.push_back({"scale 1.3", similarity(0, 1.3, 0, 0)});
  cases.push_back({"rotate 8 scale 1.15 shift", similarity(8, 1.15, -12, 9)});
  cv::Matx33d persp = similarity(0, 1.0, 0, 0);
  persp(2, 0) = 2e-4;  // a mild homography (out-of-plane tilt)
  persp(2, 1) = -1e-4;
  cases.push_back({"homography", persp});
  for (const Case& k : cases) {
    cv::Mat warped;
    cv::warpPerspective(img, warped, k.H, img.size(), cv::INTER_LINEAR,
                        cv::BORDER_REPLICATE);
    t->Reset();
    FaceInfo fi;
    ASSERT_TRUE(t->Process(warped, At(1.0), nullptr, nullptr, &fi).ok());
    ASSERT_TRUE(fi.valid) << k.name;
    // Centre: the transformed landmarks' centre.
    Eigen::Vector2d expected_c = Eigen::Vector2d::Zero();
    double err2 = 0.0;
    for (size_t i = 0; i < 68; ++i) {
      const Eigen::Vector2d p = Apply(k.H, ref.landmarks_px[i]);
      expected_c += p / 68.0;
      err2 += (fi.landmarks_px[i] - p).squaredNorm();
    }
    const double centre_err = (fi.centre_px - expected_c).norm();
    const double rms = std::sqrt(err2 / 68.0);
    const double iod = (ref.landmarks_px[45] - ref.landmarks_px[36]).norm();
    std::cout << "[ equivariance ] " << k.name << ": centre error " << centre_err
              << " px, landmark RMS " << rms << " px (" << rms / iod
              << " of the inter-ocular distance " << iod << " px)\n";
    EXPECT_LT(centre_err, 1.0) << k.name;
    EXPECT_LT(rms / iod, 0.03) << k.name;
  }
}

// A rendered sequence: the astronaut's head on a billboard 0.45 m away,
// moving sideways and bobbing, the camera shaking (known gyro).
struct Rendered {
  std::vector<cv::Mat> frames;
  std::vector<Eigen::Vector2d> truth_centre;
};

// A flat block 0.1 m in front of the face from frame `from`: width x height
// [m], its centre `dx(t)` [m] beside the face's.
struct Occluder {
  int from = 1 << 30;
  double width_m = 0.3, height_m = 0.3;
  /// Empty: a flat skin tone; else a picture, cut to the block's size.
  cv::Mat texture;
  std::function<double(double)> dx = [](double) { return 0.0; };
};

Rendered RenderMovingFace(const CameraModel& m, const OrientationTimeline& tl,
                          const RowTiming& timing, int n, double fps,
                          const Occluder& occluder = Occluder()) {
  static const cv::Mat photo = LoadImage("astronaut.png");
  static const cv::Mat bg_photo = LoadImage("building.jpg");
  const sim::InfiniteBackground bg(bg_photo, 600.0);
  // Head region of the portrait; the face (~88 px there) becomes 0.15 m.
  const cv::Rect region(139, 38, 168, 188);
  sim::Billboard face = sim::MakeFaceBillboard(photo, region, 168 * 0.15 / 88.0);
  face.pose = [](double t) {
    sim::Pose P;
    P.p = Eigen::Vector3d(0.04 * std::sin(2 * M_PI * 0.5 * t),
                          0.01 * std::sin(2 * M_PI * 1.7 * t), 0.45);
    P.R = ExpSO3(Eigen::Vector3d(0.0, 0.1 * std::sin(2 * M_PI * 0.3 * t), 0.0));
    return P;
  };
  // The ground-truth head centre: the portrait's landmark centre.
  const Eigen::Vector2d centre_uv(224.1 - region.x, 127.4 - region.y);
  const CameraIntrinsics& k = m.intrinsics();
  Rendered r;
  for (int i = 0; i < n; ++i) {
    const Time stamp = At(0.1 + i / fps);
    auto row_time = [&](double y) { return ToSeconds(timing.RowTime(stamp, y)); };
    auto cam = [&](double t) {
      sim::Pose C;
      Eigen::Quaterniond R_r;
      tl.RealRotation(Time(FromSeconds(t)), &R_r);
      C.R = R_r.conjugate();
      return C;
    };
    cv::Mat frame;
    std::vector<const sim::Billboard*> boards = {&face};
    sim::Billboard block;
    if (i >= occluder.from) {
      // 1 cm pixels, a flat skin tone; a picture at 2.5 mm pixels.
      const int k = occluder.texture.empty() ? 1 : 4;
      const int w = k * static_cast<int>(std::lround(occluder.width_m * 100));
      const int h = k * static_cast<int>(std::lround(occluder.height_m * 100));
      block.bgra = cv::Mat(h, w, CV_8UC4, cv::Scalar(40, 90, 160, 255));
      if (!occluder.texture.empty()) {
        const cv::Mat& tex = occluder.texture;
        cv::cvtColor(tex(cv::Rect(tex.cols / 2, tex.rows / 2, w, h)), block.bgra,
                     cv::COLOR_BGR2BGRA);
      }
      block.metres_per_px = 0.01 / k;
      block.anchor_px = Eigen::Vector2d(0.5 * w - 0.5, 0.5 * h - 0.5);
      block.pose = [&face, &occluder](double t) {
        sim::Pose P = face.pose(t);
        P.p.z() -= 0.1;  // in front of the face
        P.p.x() += occluder.dx(t);
        P.R = Eigen::Quaterniond::Identity();
        return P;
      };
      boards.push_back(&block);
    }
    sim::RenderScene(k, row_time, cam, bg, boards, 8, &frame);
    r.frames.push_back(frame);
    Eigen::Vector2d px;
    sim::ProjectRollingShutter(k, row_time, cam,
                               [&](double t) { return face.WorldPoint(centre_uv, t); },
                               &px);
    r.truth_centre.push_back(px);
  }
  return r;
}

OrientationTimeline ShakyTimeline() {
  OrientationTimeline tl{OrientationTimelineOptions()};
  for (int i = 0; i <= 1000; ++i) {
    const double t = i / 200.0;
    tl.AddSample({At(t), Eigen::Vector3d(0.3 * std::sin(2 * M_PI * 3 * t),
                                         0.4 * std::cos(2 * M_PI * 2 * t),
                                         0.1 * std::sin(2 * M_PI * 5 * t))});
  }
  return tl;
}

TEST(FaceTrackerTest, TracksARenderedMovingFaceWithoutRedetecting) {
  const CameraModel m = ModelFor(640, 360);
  const OrientationTimeline tl = ShakyTimeline();
  RollingShutterOptions rs;
  rs.readout_time_s = 0.02;
  const RowTiming timing(rs, 360);
  const int n = 45;
  const Rendered seq = RenderMovingFace(m, tl, timing, n, 30.0);
  FaceTrackerOptions o;
  o.redetect_every_frames = 15;
  auto t = Tracker(m, o);
  int detections = 0, valid = 0;
  double err_sum = 0.0, err_max = 0.0, track_ms = 0.0;
  int tracked_only = 0;
  std::vector<double> errs;
  for (int i = 0; i < n; ++i) {
    FaceInfo fi;
    ASSERT_TRUE(t->Process(seq.frames[i], At(0.1 + i / 30.0), &tl, &timing, &fi).ok());
    detections += fi.detected;
    if (!fi.valid) continue;
    ++valid;
    const double e = (fi.centre_px - seq.truth_centre[i]).norm();
    errs.push_back(e);
    err_sum += e;
    err_max = std::max(err_max, e);
    if (!fi.detected) {
      track_ms += fi.timings.total_ms;
      ++tracked_only;
    }
  }
  std::cout << "[ tracking ] " << valid << "/" << n << " frames valid, "
            << detections << " detections; centre error vs ground truth mean "
            << err_sum / std::max(1, valid) << " px, max " << err_max
            << " px; tracking-only frames " << track_ms / std::max(1, tracked_only)
            << " ms each\n";
  EXPECT_EQ(valid, n);
  // Acquisition + one periodic re-detection every 15 frames, no failures.
  EXPECT_LE(detections, 1 + n / 15);
  EXPECT_LT(err_sum / valid, 1.5);
  EXPECT_LT(err_max, 3.0);
}

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
  // Measured: 3 frames followed at the last fit's 4.4 px (the cover had
  // begun to drag it), then 9 held until the face is fitted again. With
  // the gate on covered faces only, the landmarks the cover dragged read
  // as a turn, the turned follow took the cover's tracks and ran 258 px
  // off the face.
  EXPECT_GT(r.held, 0);
  EXPECT_LT(r.worst_fitted, 5.0);
  EXPECT_LT(r.worst_followed, r.worst_fitted + 0.5);
}

TEST(FaceTrackerTest, NoFaceGivesSearching) {
  cv::Mat bg;
  cv::resize(LoadImage("building.jpg"), bg, cv::Size(640, 360));
  const CameraModel m = ModelFor(640, 360);
  // The default search interval (0.1 s) at 30 fps: the full-frame search
  // runs on frames 0, 3, 6, ..., a small-face tile on frames 2, 5, 8, ...
  // (half an interval later); frames 1, 4, 7, ... say not_searched.
  auto t = Tracker(m);
  ASSERT_DOUBLE_EQ(FaceTrackerOptions().search_interval_s, 0.1);
  for (int i = 0; i < 8; ++i) {
    FaceInfo fi;
    ASSERT_TRUE(t->Process(bg, At(1.0 + i / 30.0), nullptr, nullptr, &fi).ok());
    EXPECT_EQ(fi.state, TrackingState::kSearching);
    EXPECT_FALSE(fi.valid);
    EXPECT_TRUE(fi.landmarks_px.empty());
    const bool searched = i % 3 != 1;
    EXPECT_EQ(fi.detected, searched) << i;
    EXPECT_EQ(fi.failure, searched ? FaceFailure::kNoFace : FaceFailure::kNotSearched) << i;
    EXPECT_EQ(fi.timings.detect_ms > 0.0, searched) << i;
  }
  // search_interval 0: every frame searches.
  FaceTrackerOptions every;
  every.search_interval_s = 0.0;
  auto u = Tracker(m, every);
  for (int i = 0; i < 3; ++i) {
    FaceInfo fi;
    ASSERT_TRUE(u->Process(bg, At(1.0 + i / 30.0), nullptr, nullptr, &fi).ok());
    EXPECT_TRUE(fi.detected);
    EXPECT_EQ(fi.failure, FaceFailure::kNoFace);
  }
  FaceTrackerOptions bad;
  bad.search_interval_s = -1.0;
  std::unique_ptr<FaceTracker> none;
  EXPECT_FALSE(FaceTracker::Create(m, bad, &none).ok());
}

// Two copies of the portrait's head pasted on a background at given scales.
cv::Mat TwoFaces(double scale_a, cv::Point centre_a, double scale_b,
                 cv::Point centre_b, bool draw_a = true) {
  static const cv::Mat photo = LoadImage("astronaut.png");
  cv::Mat canvas;
  cv::resize(LoadImage("leuvenA.jpg"), canvas, cv::Size(960, 540));
  const cv::Rect region(139, 38, 168, 188);
  auto paste = [&](double s, cv::Point c) {
    cv::Mat head;
    cv::resize(photo(region), head, cv::Size(), s, s, cv::INTER_AREA);
    cv::Rect dst(c.x - head.cols / 2, c.y - head.rows / 2, head.cols, head.rows);
    dst &= cv::Rect(0, 0, canvas.cols, canvas.rows);
    head(cv::Rect(0, 0, dst.width, dst.height)).copyTo(canvas(dst));
  };
  if (draw_a) paste(scale_a, centre_a);
  paste(scale_b, centre_b);
  return canvas;
}

TEST(FaceTrackerTest, LargestFaceIsLockedAndKeptUntilLost) {
  const CameraModel m = ModelFor(960, 540);
  FaceTrackerOptions o;
  o.lost_timeout_s = 0.3;
  o.redetect_every_frames = 3;  // re-detection often: it must not switch
  auto t = Tracker(m, o);
  const cv::Point a(300, 260), b(700, 260);
  double time = 1.0;
  FaceInfo fi;
  // Frame 0: A large, B small: lock A.
  ASSERT_TRUE(t->Process(TwoFaces(1.6, a, 1.0, b), At(time), nullptr, nullptr, &fi).ok());
  ASSERT_TRUE(fi.valid);
  EXPECT_LT(std::abs(fi.centre_px.x() - a.x), 60);
  // B grows to twice A's size over 12 frames: the lock stays on A.
  for (int i = 1; i <= 12; ++i) {
    time += 1.0 / 30;
    const double sb = 1.0 + 2.2 * i / 12.0;
    ASSERT_TRUE(t->Process(TwoFaces(1.6, a, sb, b), At(time), nullptr, nullptr, &fi).ok());
    ASSERT_TRUE(fi.valid) << i;
    EXPECT_LT(std::abs(fi.centre_px.x() - a.x), 60) << "frame " << i;
  }
  // A leaves: lost, and B is not taken before the timeout...
  int reacquired_at = -1;
  for (int i = 0; i < 20; ++i) {
    time += 1.0 / 30;
    ASSERT_TRUE(t->Process(TwoFaces(1.6, a, 3.2, b, false), At(time), nullptr, nullptr, &fi).ok());
    if (fi.valid) {
      EXPECT_LT(std::abs(fi.centre_px.x() - b.x), 80);
      if (reacquired_at < 0) reacquired_at = i;
    } else {
      EXPECT_NE(fi.state, TrackingState::kTracking);
    }
  }
  // ... then B is acquired (0.3 s = 9 frames at 30 fps).
  std::cout << "[ two faces ] re-acquired the other face after " << reacquired_at
            << " frames\n";
  EXPECT_GE(reacquired_at, 8);
  EXPECT_LE(reacquired_at, 12);
}

TEST(FaceTrackerTest, BadInputIsAnErrorNotACrash) {
  const CameraModel m = ModelFor(640, 360);
  auto t = Tracker(m);
  FaceInfo fi;
  EXPECT_FALSE(t->Process(cv::Mat(), At(1), nullptr, nullptr, &fi).ok());
  EXPECT_EQ(fi.failure, FaceFailure::kBadInput);
  EXPECT_FALSE(t->Process(cv::Mat(1, 1, CV_8UC3), At(1), nullptr, nullptr, &fi).ok());
  EXPECT_FALSE(t->Process(cv::Mat(360, 640, CV_16UC1), At(1), nullptr, nullptr, &fi).ok());
  EXPECT_FALSE(t->Process(cv::Mat(360, 640, CV_32FC3), At(1), nullptr, nullptr, &fi).ok());
  EXPECT_FALSE(fi.valid);
  // A 1x1 camera: valid input for the model, nothing to find.
  const CameraModel tiny = ModelFor(1, 1);
  auto t1 = Tracker(tiny);
  EXPECT_TRUE(t1->Process(cv::Mat(1, 1, CV_8UC1, cv::Scalar(7)), At(1), nullptr, nullptr, &fi).ok());
  EXPECT_FALSE(fi.valid);
  // External landmarks of the wrong count.
  EXPECT_FALSE(t->ProcessExternal(std::vector<Eigen::Vector2d>(5), 1.0, At(2), nullptr,
                                  nullptr, &fi).ok());
}

TEST(FaceTrackerTest, MissingOrCorruptModelNamesFileAndPackage) {
  const CameraModel m = ModelFor(640, 360);
  FaceTrackerOptions o;
  o.landmark_model_path = "/nonexistent/shape_predictor.dat";
  std::unique_ptr<FaceTracker> t;
  Status s = FaceTracker::Create(m, o, &t);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("/nonexistent/shape_predictor.dat"), std::string::npos);
  EXPECT_NE(s.message().find("libdlib-data"), std::string::npos);
  o.landmark_model_path = testing_util::DataPath("README.md");  // not a model
  s = FaceTracker::Create(m, o, &t);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("not a valid"), std::string::npos) << s.message();
  o = FaceTrackerOptions();
  o.detector.type = FaceDetectorType::kOpenCvCascade;
  o.detector.cascade_path = "/nonexistent.xml";
  s = FaceTracker::Create(m, o, &t);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("opencv-data"), std::string::npos);
}

TEST(FaceTrackerTest, OpenCvCascadeDetectorAlsoFindsTheFace) {
  const cv::Mat img = LoadImage("astronaut.png");
  const CameraModel m = ModelFor(img.cols, img.rows);
  FaceTrackerOptions o;
  o.detector.type = FaceDetectorType::kOpenCvCascade;
  auto t = Tracker(m, o);
  FaceInfo fi;
  ASSERT_TRUE(t->Process(img, At(1.0), nullptr, nullptr, &fi).ok());
  ASSERT_TRUE(fi.valid) << FaceFailureName(fi.failure);
  EXPECT_GT(fi.centre_px.x(), 180);
  EXPECT_LT(fi.centre_px.x(), 270);
}

TEST(FaceTrackerTest, ExternalLandmarksUseTheSameChecks) {
  const cv::Mat img = LoadImage("astronaut.png");
  const CameraModel m = ModelFor(img.cols, img.rows);
  auto t = Tracker(m);
  FaceInfo ref;
  ASSERT_TRUE(t->Process(img, At(1.0), nullptr, nullptr, &ref).ok());
  auto ext = Tracker(m);
  FaceInfo fi;
  ASSERT_TRUE(ext->ProcessExternal(ref.landmarks_px, 0.9, At(1.0), nullptr, nullptr, &fi).ok());
  EXPECT_TRUE(fi.valid);
  EXPECT_NEAR((fi.centre_px - ref.centre_px).norm(), 0.0, 1e-9);
  // Shifted by 3 px: still the face.
  std::vector<Eigen::Vector2d> moved = ref.landmarks_px;
  for (auto& p : moved) p += Eigen::Vector2d(3, 0);
  ASSERT_TRUE(ext->ProcessExternal(moved, 0.9, At(1.03), nullptr, nullptr, &fi).ok());
  EXPECT_TRUE(fi.valid);
  // Scrambled points: implausible.
  std::vector<Eigen::Vector2d> scrambled = ref.landmarks_px;
  std::reverse(scrambled.begin(), scrambled.end());
  ASSERT_TRUE(ext->ProcessExternal(scrambled, 0.9, At(1.06), nullptr, nullptr, &fi).ok());
  EXPECT_FALSE(fi.valid);
  EXPECT_EQ(fi.failure, FaceFailure::kImplausibleShape);
  // A jump across the image: rejected.
  std::vector<Eigen::Vector2d> far = ref.landmarks_px;
  for (auto& p : far) p += Eigen::Vector2d(200, 150);
  ASSERT_TRUE(ext->ProcessExternal(far, 0.9, At(1.09), nullptr, nullptr, &fi).ok());
  EXPECT_FALSE(fi.valid);
  EXPECT_EQ(fi.failure, FaceFailure::kJump);
  // Nothing: lost.
  ASSERT_TRUE(ext->ProcessExternal({}, 0.0, At(1.12), nullptr, nullptr, &fi).ok());
  EXPECT_EQ(fi.state, TrackingState::kLost);
}

TEST(HeadPoseTest, RecoversKnownRotationsOfTheGenericFace) {
  const CameraIntrinsics k = IntrinsicsFromHorizontalFov(640, 480, 1.0);
  const auto& model = GenericFace68();
  for (const Eigen::Vector3d& ypr :
       {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.4, 0.0, 0.0),
        Eigen::Vector3d(-0.3, 0.2, 0.0), Eigen::Vector3d(0.1, -0.25, 0.15)}) {
    const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(ypr[0], Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(ypr[1], Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(ypr[2], Eigen::Vector3d::UnitZ()))
            .toRotationMatrix();
    const Eigen::Vector3d pos(0.0, 0.0, 0.6);  // on the optical axis
    std::vector<Eigen::Vector2d> px;
    for (const auto& X : model) {
      const Eigen::Vector3d c = R * X + pos;
      px.emplace_back(k.fx * c.x() / c.z() + k.cx, k.fy * c.y() / c.z() + k.cy);
    }
    double yaw, pitch, roll;
    ASSERT_TRUE(EstimateHeadPose(model, px, k, &yaw, &pitch, &roll));
    EXPECT_NEAR(yaw, ypr[0], 0.02);
    EXPECT_NEAR(pitch, ypr[1], 0.02);
    EXPECT_NEAR(roll, ypr[2], 0.02);
  }
}

}  // namespace
}  // namespace steadiface

#include "steadiface_core/face/face_tracker.h"

#include <cmath>
#include <iostream>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/face/face_detector.h"
#include "steadiface_core/face/generic_face.h"
#include "steadiface_core/face/head_pose.h"
#include "steadiface_core/face/landmark_predictor.h"
#include "steadiface_core/sim/head_relief.h"
#include "rendered_face.h"
#include "test_util.h"

namespace steadiface {
namespace {

using testing_util::At;
using testing_util::LoadImage;
using testing_util::ModelFor;
using testing_util::RenderMovingFace;
using testing_util::Rendered;
using testing_util::ShakyTimeline;
using testing_util::Tracker;

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

TEST(PortraitLandmarksTest, TheSimulatorsAreWhatDlibFinds) {
  // test/data/astronaut_landmarks68.txt (the simulated mean-face head
  // uses it) is what the face detector and dlib's 68-point model find on
  // the portrait, to 0.5 px (other dlib builds may differ by a little).
  const cv::Mat photo = cv::imread(testing_util::DataPath("astronaut.png"), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(photo.empty());
  std::unique_ptr<FaceDetector> detector;
  ASSERT_TRUE(FaceDetector::Create(FaceDetectorOptions(), &detector).ok());
  std::vector<FaceBox> boxes;
  ASSERT_TRUE(detector->Detect(photo, cv::Rect(0, 0, photo.cols, photo.rows), &boxes).ok());
  ASSERT_FALSE(boxes.empty());
  std::unique_ptr<LandmarkPredictor> predictor;
  ASSERT_TRUE(LandmarkPredictor::Load(kDefaultShapePredictorPath, &predictor).ok());
  std::vector<Eigen::Vector2d> found;
  ASSERT_TRUE(predictor->Predict(photo, boxes[0].rect, &found).ok());
  std::vector<Eigen::Vector2d> stored;
  sim::ReadPhotoLandmarks(testing_util::DataPath("astronaut_landmarks68.txt"), &stored);
  ASSERT_EQ(stored.size(), found.size());
  for (size_t i = 0; i < stored.size(); ++i) EXPECT_LT((stored[i] - found[i]).norm(), 0.5) << i;
}

}  // namespace
}  // namespace steadiface

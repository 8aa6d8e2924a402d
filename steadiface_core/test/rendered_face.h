#pragma once
// A face rendered moving in front of a shaking camera (known gyro), with an
// optional block passing in front of it, and the tracker to follow it: the
// face tracker's tests (face_tracker_test.cc, face_cover_test.cc).

#include <cmath>
#include <functional>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/common/so3.h"
#include "steadiface_core/face/face_tracker.h"
#include "steadiface_core/gyro/orientation_timeline.h"
#include "steadiface_core/sim/scene_renderer.h"
#include "test_util.h"

namespace steadiface {
namespace testing_util {

inline CameraModel ModelFor(int w, int h, double hfov = 1.0) {
  CameraModel m;
  EXPECT_TRUE(CameraModel::Create(IntrinsicsFromHorizontalFov(w, h, hfov),
                                  CameraModelOptions(), &m)
                  .ok());
  return m;
}

inline std::unique_ptr<FaceTracker> Tracker(const CameraModel& m,
                                     FaceTrackerOptions o = FaceTrackerOptions()) {
  std::unique_ptr<FaceTracker> t;
  const Status s = FaceTracker::Create(m, o, &t);
  EXPECT_TRUE(s.ok()) << s.message();
  return t;
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

inline Rendered RenderMovingFace(const CameraModel& m, const OrientationTimeline& tl,
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

inline OrientationTimeline ShakyTimeline() {
  OrientationTimeline tl{OrientationTimelineOptions()};
  for (int i = 0; i <= 1000; ++i) {
    const double t = i / 200.0;
    tl.AddSample({At(t), Eigen::Vector3d(0.3 * std::sin(2 * M_PI * 3 * t),
                                         0.4 * std::cos(2 * M_PI * 2 * t),
                                         0.1 * std::sin(2 * M_PI * 5 * t))});
  }
  return tl;
}

}  // namespace testing_util
}  // namespace steadiface

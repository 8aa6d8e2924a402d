#include "steadiface_core/pipeline/debug_overlay.h"

#include <memory>

#include <gtest/gtest.h>

#include "steadiface_core/warp/warper.h"

namespace steadiface {
namespace {

TEST(DebugOverlayTest, DrawsLandmarksCentreTargetAndFootprint) {
  const CameraIntrinsics k = IntrinsicsFromHorizontalFov(640, 480, 1.1);
  CameraModel m;
  ASSERT_TRUE(CameraModel::Create(k, CameraModelOptions(), &m).ok());
  WarpOptions wo;
  wo.output.crop_ratio = 0.1;
  std::unique_ptr<Warper> w;
  ASSERT_TRUE(Warper::Create(m, wo, &w).ok());
  const cv::Mat input(480, 640, CV_8UC1, cv::Scalar(128));
  FaceInfo face;
  face.valid = true;
  face.state = TrackingState::kTracking;
  face.confidence = 0.9;
  face.landmarks_px = {Eigen::Vector2d(300, 200), Eigen::Vector2d(340, 210)};
  face.centre_px = Eigen::Vector2d(320, 205);
  StabilizerFrame f;
  f.R_v = f.R_r = Eigen::Quaterniond::Identity();
  f.rows = RowRotations(f.R_r, 480);
  f.has_target = true;
  f.H = m.PixelToNormalized({400, 300});
  f.solver.termination = "CONVERGENCE";
  cv::Mat out;
  DrawDebugOverlay(input, m, w->protrusion(), &face, &f, &out);
  ASSERT_EQ(out.type(), CV_8UC3);
  auto changed = [&](int x, int y) {
    return out.at<cv::Vec3b>(y, x) != cv::Vec3b(128, 128, 128);
  };
  EXPECT_TRUE(changed(300, 200));  // landmark
  EXPECT_TRUE(changed(320, 205));  // C
  EXPECT_TRUE(changed(410, 300));  // H circle (radius 10)
  // Identity pose, crop 0.1: the footprint is the centre crop rectangle
  // through the outer output pixel centres (x ~ 64, y ~ 48).
  EXPECT_TRUE(changed(64, 240));
  EXPECT_TRUE(changed(320, 48));
  EXPECT_FALSE(changed(200, 240));  // untouched interior
  EXPECT_TRUE(changed(20, 18));     // text
  // A followed head's landmarks are drawn too, in orange (BGR 0, 140, 255),
  // where a fitted face's are green; a face neither fitted nor followed is
  // not drawn.
  const cv::Vec3b green_dot = out.at<cv::Vec3b>(200, 300);
  face.valid = false;
  face.followed = true;
  face.state = TrackingState::kLost;
  DrawDebugOverlay(input, m, w->protrusion(), &face, &f, &out);
  const cv::Vec3b orange_dot = out.at<cv::Vec3b>(200, 300);
  EXPECT_GT(green_dot[1], green_dot[2]);
  EXPECT_GT(orange_dot[2], orange_dot[1]);
  EXPECT_GT(orange_dot[2], 200);
  face.followed = false;
  DrawDebugOverlay(input, m, w->protrusion(), &face, &f, &out);
  EXPECT_FALSE(changed(300, 200));
  // Null inputs draw nothing but the copy.
  DrawDebugOverlay(input, m, w->protrusion(), nullptr, nullptr, &out);
  EXPECT_EQ(cv::norm(out, cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(128)), cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace steadiface

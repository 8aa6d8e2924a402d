// The lens model (lens_distortion.h) against OpenCV's own projection of the
// same coefficients, and its inverse: Undistort(Distort(m)) = m.
#include "steadiface_core/camera/lens_distortion.h"

#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "steadiface_core/camera/camera_model.h"

namespace steadiface {
namespace {

CameraIntrinsics Lens(DistortionModel model, std::vector<double> coeffs) {
  CameraIntrinsics k;
  k.width = 640;
  k.height = 480;
  k.fx = k.fy = 500.0;
  k.cx = 320.0;
  k.cy = 240.0;
  k.distortion = model;
  k.distortion_coeffs = std::move(coeffs);
  return k;
}

// Ideal camera points over the frame's field of view.
std::vector<Eigen::Vector2d> Grid() {
  std::vector<Eigen::Vector2d> m;
  for (double x = -0.6; x <= 0.6; x += 0.15) {
    for (double y = -0.45; y <= 0.45; y += 0.15) m.emplace_back(x, y);
  }
  return m;
}

// OpenCV's distorted pixel of camera point m.
cv::Point2d OpenCvPixel(const CameraIntrinsics& k, const Eigen::Vector2d& m) {
  const std::vector<cv::Point3d> object = {cv::Point3d(m.x(), m.y(), 1.0)};
  const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  std::vector<cv::Point2d> image;
  if (k.distortion == DistortionModel::kEquidistant) {
    cv::fisheye::projectPoints(object, image, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K,
                               k.distortion_coeffs);
  } else {
    cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, k.distortion_coeffs,
                      image);
  }
  return image[0];
}

TEST(LensDistortionTest, MatchesOpenCvAndInvertsForEveryModel) {
  for (const CameraIntrinsics& k :
       {Lens(DistortionModel::kPlumbBob, {-0.28, 0.09, 0.001, -0.0005, -0.01}),
        Lens(DistortionModel::kPlumbBob, {0.1, -0.05, 0.0, 0.0, 0.0, 0.02, 0.0, 0.0}),
        Lens(DistortionModel::kEquidistant, {0.05, -0.01, 0.004, -0.001})}) {
    for (const Eigen::Vector2d& m : Grid()) {
      const Eigen::Vector2d d = DistortCameraPoint<double>(k, m);
      const cv::Point2d cv_px = OpenCvPixel(k, m);
      EXPECT_NEAR(k.fx * d.x() + k.cx, cv_px.x, 1e-9) << m.transpose();
      EXPECT_NEAR(k.fy * d.y() + k.cy, cv_px.y, 1e-9) << m.transpose();
      Eigen::Vector2d back;
      ASSERT_TRUE(UndistortCameraPoint(k, d, &back)) << m.transpose();
      EXPECT_LT((back - m).norm(), 1e-9) << m.transpose();
    }
  }
}

// A pixel as the lens recorded it (OpenCV's projection) is normalized where
// its undistorted pixel is (CameraModel::RawPixelToNormalized); without a
// lens model the raw pixel is the ideal one.
TEST(LensDistortionTest, ARawPixelIsNormalizedWhereItsIdealPixelIs) {
  for (const CameraIntrinsics& k : {Lens(DistortionModel::kPlumbBob, {-0.28, 0.09, 0.001, -0.0005, -0.01}),
                                    Lens(DistortionModel::kNone, {})}) {
    CameraModel model;
    ASSERT_TRUE(CameraModel::Create(k, CameraModelOptions(), &model).ok());
    for (const Eigen::Vector2d& m : Grid()) {
      const cv::Point2d raw = OpenCvPixel(k, m);
      const Eigen::Vector2d ideal(k.fx * m.x() + k.cx, k.fy * m.y() + k.cy);
      Eigen::Vector2d n;
      ASSERT_TRUE(model.RawPixelToNormalized(Eigen::Vector2d(raw.x, raw.y), &n)) << m.transpose();
      EXPECT_LT((n - model.PixelToNormalized(ideal)).norm(), 1e-9) << m.transpose();
    }
  }
}

TEST(LensDistortionTest, WithoutDistortionEveryMapIsTheIdentity) {
  const CameraIntrinsics k = Lens(DistortionModel::kNone, {});
  const Eigen::Vector2d m(0.3, -0.2), px(100.5, 37.25);
  EXPECT_EQ(DistortCameraPoint<double>(k, m), m);
  Eigen::Vector2d out;
  ASSERT_TRUE(UndistortPixel(k, px, &out));
  EXPECT_EQ(out, px);
}

}  // namespace
}  // namespace steadiface

#include "steadiface_core/sim/head_relief.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/camera/camera_intrinsics.h"

namespace steadiface {
namespace sim {
namespace {

// A textured board 0.3 m in front of a still camera (global shutter).
struct Scene {
  CameraIntrinsics k = IntrinsicsFromHorizontalFov(320, 240, 1.0);
  Billboard board;
  std::function<double(double)> row_time = [](double) { return 0.0; };
  std::function<Pose(double)> camera = [](double) { return Pose(); };

  explicit Scene(const Eigen::Quaterniond& R = Eigen::Quaterniond::Identity()) {
    cv::Mat bgr(120, 100, CV_8UC3);
    cv::RNG rng(7);  // the same texture in every scene
    rng.fill(bgr, cv::RNG::UNIFORM, 0, 255);
    cv::GaussianBlur(bgr, bgr, cv::Size(), 2.0);
    cv::cvtColor(bgr, board.bgra, cv::COLOR_BGR2BGRA);
    board.metres_per_px = 0.002;
    board.anchor_px = Eigen::Vector2d(49.5, 59.5);
    board.pose = [R](double) {
      Pose P;
      P.R = R;
      P.p = Eigen::Vector3d(0.0, 0.0, 0.5);
      return P;
    };
  }
};

TEST(HeadReliefTest, AFlatReliefDrawsWhatThePlaneDraws) {
  // The triangle rasterizer against the plane's inverse map: the same
  // coverage, and the same colours inside.
  Scene flat;
  Scene relief;
  relief.board.depth_m = cv::Mat::zeros(relief.board.bgra.size(), CV_32F);
  cv::Mat a_flat, a_relief;
  RenderAlpha(flat.k, flat.row_time, flat.camera, {&flat.board}, 8, &a_flat);
  RenderAlpha(relief.k, relief.row_time, relief.camera, {&relief.board}, 8,
              &a_relief);
  EXPECT_GT(cv::countNonZero(a_flat), 5000);
  cv::Mat diff;
  cv::absdiff(a_flat, a_relief, diff);
  // Only the outline's pixels may differ (half a pixel of edge).
  EXPECT_LT(cv::countNonZero(diff > 128), 0.02 * cv::countNonZero(a_flat));
  InfiniteBackground plain(cv::Mat(64, 64, CV_8UC3, cv::Scalar::all(0)), 100.0);
  cv::Mat c_flat, c_relief;
  RenderScene(flat.k, flat.row_time, flat.camera, plain, {&flat.board}, 8,
              &c_flat);
  RenderScene(relief.k, relief.row_time, relief.camera, plain, {&relief.board},
              8, &c_relief);
  cv::Mat inside;
  cv::erode(a_flat == 255, inside, cv::Mat(), cv::Point(-1, -1), 2);
  cv::absdiff(c_flat, c_relief, diff);
  std::vector<cv::Mat> channels;
  cv::split(diff, channels);
  double worst = 0.0;
  for (const cv::Mat& c : channels) {
    double w = 0.0;
    cv::minMaxLoc(c, nullptr, &w, nullptr, nullptr, inside);
    worst = std::max(worst, w);
  }
  EXPECT_LE(worst, 3.0);
  EXPECT_LT(cv::mean(diff, inside)[0], 0.2);
}

TEST(HeadReliefTest, TheNearestSurfaceHidesWhatIsBehindIt) {
  // A board whose texels show their own column (blue = u) with a ridge down
  // its middle, turned 60 deg: along the middle row every texel is either
  // drawn where it projects, or hidden there by a texel nearer the camera.
  Scene s(Eigen::Quaterniond(
      Eigen::AngleAxisd(60.0 * M_PI / 180.0, Eigen::Vector3d::UnitY())));
  for (int v = 0; v < s.board.bgra.rows; ++v) {
    for (int u = 0; u < s.board.bgra.cols; ++u) {
      s.board.bgra.at<cv::Vec4b>(v, u) =
          cv::Vec4b(static_cast<uchar>(u), 128, 128, 255);
    }
  }
  s.board.depth_m = cv::Mat(s.board.bgra.size(), CV_32F);
  for (int v = 0; v < s.board.bgra.rows; ++v) {
    for (int u = 0; u < s.board.bgra.cols; ++u) {
      s.board.depth_m.at<float>(v, u) = static_cast<float>(
          -0.04 * std::exp(-0.5 * std::pow((u - 50) / 5.0, 2)));
    }
  }
  cv::Mat layer;
  RenderRelief(s.k, s.row_time, s.camera, s.board, 8, &layer);
  auto seen = [&](int u, Eigen::Vector2d* px) {
    const Eigen::Vector3d X = s.board.WorldPoint(Eigen::Vector2d(u, 60), 0.0);
    *px = Eigen::Vector2d(s.k.fx * X.x() / X.z() + s.k.cx,
                          s.k.fy * X.y() / X.z() + s.k.cy);
    return X.z();
  };
  int hidden = 0, drawn = 0;
  for (int u = 2; u < 98; ++u) {
    Eigen::Vector2d px;
    const double z = seen(u, &px);
    const cv::Vec4b shown =
        layer.at<cv::Vec4b>(static_cast<int>(std::lround(px.y())),
                            static_cast<int>(std::lround(px.x())));
    ASSERT_EQ(shown[3], 255) << u;
    if (std::abs(shown[0] - u) <= 2) {
      ++drawn;
      continue;
    }
    ++hidden;
    Eigen::Vector2d px_front;
    EXPECT_LT(seen(shown[0], &px_front), z - 0.005)
        << "texel " << u << " shows texel " << int(shown[0]);
    EXPECT_LT((px_front - px).norm(), 2.0) << u;
  }
  EXPECT_GT(hidden, 5);
  EXPECT_GT(drawn, 50);
}

TEST(HeadReliefTest, TheBreadthSetsWhereTheSidesReachThePivot) {
  // Across the ellipse's middle row, away from the nose, the depth is the
  // pivot's times 1 - sqrt(1 - (x / half breadth)^2): at the half breadth
  // the pivot's own, at half of it 0.134 of it. Without a breadth the
  // outline is outline_radius of the texture's half width.
  const cv::Size size(169, 189);  // odd: the middle row and column are texels
  const Eigen::Vector2d centre(84.0, 40.0);  // the nose far above the middle row
  const double w = 88.0;                     // face width [texels]
  HeadReliefOptions o;
  o.nose_below = 0.0;
  const double cx = 84.0;
  const int row = 94;
  for (double breadth : {1.0, 1.25}) {  // half breadths of whole texels
    o.breadth_face_widths = breadth;
    const cv::Mat d = MakeHeadRelief(size, centre, w, o);
    const double half = 0.5 * breadth * w;
    EXPECT_NEAR(ReliefDepth(d, Eigen::Vector2d(cx, row)), 0.0, 1e-4);  // the nose's tail
    EXPECT_NEAR(ReliefDepth(d, Eigen::Vector2d(cx + 0.5 * half, row)),
                o.pivot_depth_m * (1.0 - std::sqrt(0.75)), 1e-3);
    EXPECT_NEAR(ReliefDepth(d, Eigen::Vector2d(cx - half, row)), o.pivot_depth_m, 1e-3);
    EXPECT_NEAR(ReliefDepth(d, Eigen::Vector2d(cx + half + 5.0, row)), o.pivot_depth_m, 1e-4);
  }
  o.breadth_face_widths = 0.0;
  const cv::Mat d = MakeHeadRelief(size, centre, w, o);
  const double half = o.outline_radius * 0.5 * size.width;
  EXPECT_NEAR(ReliefDepth(d, Eigen::Vector2d(cx + 0.5 * half, row)),
              o.pivot_depth_m * (1.0 - std::sqrt(0.75)), 1e-3);
  EXPECT_NEAR(ReliefDepth(d, Eigen::Vector2d(cx + half + 2.0, row)), o.pivot_depth_m, 1e-4);
  EXPECT_LT(ReliefDepth(d, Eigen::Vector2d(cx + 0.9 * half, row)), 0.6 * o.pivot_depth_m);
}

}  // namespace
}  // namespace sim
}  // namespace steadiface

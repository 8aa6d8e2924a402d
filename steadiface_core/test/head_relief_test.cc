#include "steadiface_core/sim/head_relief.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/sim/mean_face.h"
#include "steadiface_core/sim/simulator.h"

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

// The simulator's portrait landmarks, in its billboard's texels.
std::vector<Eigen::Vector2d> PortraitLandmarksUv(const SimulatorOptions& so) {
  std::vector<Eigen::Vector2d> uv;
  ReadPhotoLandmarks(std::string(STEADIFACE_TEST_DATA_DIR) + "/" + so.face_landmarks, &uv);
  for (Eigen::Vector2d& p : uv) p -= Eigen::Vector2d(so.face_region.x, so.face_region.y);
  return uv;
}

TEST(MeanFaceTest, IsAsDeepAsTheMeanHumanFace) {
  // A published mean 3D face of the 68 landmarks (OpenFace's in-the-wild
  // mean shape, 14.5 cm between the jaw ends) puts, relative to the eyes'
  // mean, the jaw's ends 4.6 cm behind and the nose tip 3.7 cm in front, the
  // chin 0.2 cm in front and the outer brows 1.2 cm behind.
  const auto& f = MeanFace68();
  ASSERT_EQ(f.size(), 68u);
  const double s = 0.145 / (f[16] - f[0]).head<2>().norm();
  double eyes = 0.0;
  for (int i = 36; i < 48; ++i) eyes += f[i].z() / 12.0;
  EXPECT_NEAR(eyes, 0.0, 1e-9);  // the origin's depth
  EXPECT_NEAR(s * f[0].z(), 0.046, 0.003);
  EXPECT_NEAR(s * f[16].z(), 0.046, 0.003);
  EXPECT_NEAR(s * f[30].z(), -0.037, 0.003);
  EXPECT_NEAR(s * f[8].z(), -0.002, 0.003);
  EXPECT_NEAR(s * f[17].z(), 0.012, 0.003);
}

TEST(HeadReliefTest, TheMeanFaceGivesEachLandmarkItsDepth) {
  // On the simulator's portrait each landmark's depth is the mean face's,
  // scaled from its 0.14 m jaw to the photo's: the eyes' mean on the plane.
  const SimulatorOptions so;
  const std::vector<Eigen::Vector2d> uv = PortraitLandmarksUv(so);
  ASSERT_EQ(uv.size(), 68u);
  const double mpt = so.face_width_m / so.face_width_px;
  HeadReliefOptions o = so.relief;
  o.nose_height_m = 0.0;
  o.breadth_face_widths = 1.1;
  cv::Mat d = MakeHeadRelief(cv::Size(so.face_region.width, so.face_region.height),
                             so.face_centre_px - Eigen::Vector2d(so.face_region.x, so.face_region.y),
                             so.face_width_px, o);
  const cv::Mat ellipsoid = d.clone();
  ASSERT_TRUE(AddMeanFaceDepths(uv, mpt, o.mean_face_sigma, &d));
  const auto& face = MeanFace68();
  const double scale = (uv[16] - uv[0]).norm() * mpt / (face[16] - face[0]).head<2>().norm();
  double eyes = 0.0;
  for (int i = 36; i < 48; ++i) eyes += ReliefDepth(d, uv[i]) / 12.0;
  double worst = 0.0;
  for (int i = 0; i < 68; ++i) {
    worst = std::max(worst, std::abs(ReliefDepth(d, uv[i]) - eyes - scale * face[i].z()));
  }
  EXPECT_LT(worst, 0.0015) << "m";
  EXPECT_NEAR(eyes, 0.0, 0.0015);
  // Far from the face (the texture's corner) the ellipsoid is untouched.
  EXPECT_NEAR(d.at<float>(2, 2), ellipsoid.at<float>(2, 2), 1e-6);
  // Bad landmarks leave the relief as it was.
  cv::Mat unchanged = ellipsoid.clone();
  EXPECT_FALSE(AddMeanFaceDepths(std::vector<Eigen::Vector2d>(5), mpt, 0.06, &unchanged));
  EXPECT_EQ(cv::norm(unchanged, ellipsoid, cv::NORM_INF), 0.0);
}

TEST(HeadReliefTest, AMeanFaceWithoutItsLandmarksIsAClearError) {
  SimulatorOptions so;
  so.data_dir = STEADIFACE_TEST_DATA_DIR;
  so.duration_s = 0.2;
  so.relief.mean_face = true;
  std::unique_ptr<Simulator> sim;
  EXPECT_TRUE(Simulator::Create(so, &sim).ok());
  so.face_landmarks = "no_such_landmarks.txt";
  const Status s = Simulator::Create(so, &sim);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("no_such_landmarks.txt"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace sim
}  // namespace steadiface

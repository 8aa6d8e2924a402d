#include "steadiface_core/warp/warper.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "steadiface_core/common/so3.h"
#include "steadiface_core/sim/background.h"
#include "test_util.h"

namespace steadiface {
namespace {

using testing_util::At;
using testing_util::LoadImage;

CameraModel Model(const CameraIntrinsics& k, double zoom = 1.0) {
  CameraModel m;
  CameraModelOptions o;
  o.virtual_focal_scale = zoom;
  EXPECT_TRUE(CameraModel::Create(k, o, &m).ok());
  return m;
}

std::unique_ptr<Warper> MakeWarper(const CameraModel& m, WarpOptions o) {
  std::unique_ptr<Warper> w;
  const Status s = Warper::Create(m, o, &w);
  EXPECT_TRUE(s.ok()) << s.message();
  return w;
}

double Psnr(const cv::Mat& a, const cv::Mat& b) {
  return cv::PSNR(a, b);
}

// A timeline with a fast, non-constant shake (rad/s), 1 kHz.
OrientationTimeline ShakeTimeline(double amp = 3.0) {
  OrientationTimeline tl{OrientationTimelineOptions()};
  for (int i = 0; i <= 2000; ++i) {
    const double t = i / 1000.0;
    tl.AddSample({At(t), Eigen::Vector3d(0.4 * amp * std::sin(2 * M_PI * 9 * t),
                                         amp * std::sin(2 * M_PI * 15 * t),
                                         0.2 * amp * std::cos(2 * M_PI * 4 * t))});
  }
  return tl;
}

// The background as the rolling-shutter camera sees it: each row at its
// own time on the timeline.
void RenderRows(const sim::InfiniteBackground& bg, const CameraIntrinsics& k,
                const OrientationTimeline& tl, const RowTiming& timing, Time stamp,
                cv::Mat* real) {
  bg.Render(k, [&](double y) {
    Eigen::Quaterniond R;
    tl.RealRotation(timing.RowTime(stamp, y), &R);
    return R;
  }, 1, real);
}

TEST(WarperTest, IdentityPoseGivesTheScaledCentreCrop) {
  cv::Mat photo;
  cv::resize(LoadImage("coffee.png"), photo, cv::Size(640, 480), 0, 0,
             cv::INTER_AREA);
  const CameraIntrinsics k = IntrinsicsFromHorizontalFov(640, 480, 1.2);
  const CameraModel m = Model(k);
  WarpOptions o;
  o.output.crop_ratio = 0.1;
  for (bool fixed : {true, false}) {
    o.direct_sampling = false;
    o.fixed_point_maps = fixed;
    auto w = MakeWarper(m, o);
    const Eigen::Quaterniond R = ExpSO3(Eigen::Vector3d(0.1, 0.2, -0.1));
    cv::Mat out;
    ASSERT_TRUE(w->Warp(photo, R, Eigen::Vector2d::Zero(),
                        RowRotations(R, 480), &out)
                    .ok());
    cv::Mat ref;
    cv::resize(photo(cv::Rect(64, 48, 512, 384)), ref, cv::Size(640, 480), 0,
               0, cv::INTER_LINEAR);
    const double psnr = Psnr(out, ref);
    EXPECT_GT(psnr, 40.0) << "fixed=" << fixed;
    RecordProperty(fixed ? "psnr_fixed_db" : "psnr_float_db",
                   std::to_string(psnr));
  }
}

TEST(WarperTest, OutputIntrinsicsDescribeTheOutputImage) {
  const CameraIntrinsics k = IntrinsicsFromHorizontalFov(640, 480, 1.2);
  const CameraModel m = Model(k, 1.1);
  WarpOptions o;
  o.output.crop_ratio = 0.12;
  o.output.width = 400;
  o.output.height = 300;
  auto w = MakeWarper(m, o);
  const Eigen::Vector2d t(0.02, -0.013);
  const CameraIntrinsics out_k = w->output_geometry().VirtualIntrinsics(t);
  const Eigen::Quaterniond Rv = ExpSO3(Eigen::Vector3d(0.05, -0.1, 0.02));
  // A world direction seen by the virtual camera: via K_v and the output
  // geometry, and via the published intrinsics, lands on the same pixel.
  for (const Eigen::Vector3d& d :
       {Eigen::Vector3d(0.1, 0.05, 1.0), Eigen::Vector3d(-0.2, 0.1, 1.0)}) {
    const Eigen::Vector3d c = Rv * d;
    const Eigen::Vector2d V = (m.VirtualK(t) * c).hnormalized();
    const Eigen::Vector2d uv = w->output_geometry().VirtualToOutputPixel(V);
    EXPECT_NEAR(out_k.fx * c.x() / c.z() + out_k.cx, uv.x(), 1e-9);
    EXPECT_NEAR(out_k.fy * c.y() / c.z() + out_k.cy, uv.y(), 1e-9);
  }
  EXPECT_EQ(out_k.width, 400);
  EXPECT_EQ(out_k.height, 300);
}

// Exact source pixel of output pixel (u, v): per-pixel fixed point with the
// timeline queried at the exact row time (no table, no mesh).
Eigen::Vector2d ExactSource(const CameraModel& m, const OutputGeometry& g,
                            const OrientationTimeline& tl,
                            const RowTiming& timing, Time stamp,
                            const Eigen::Quaterniond& Rv,
                            const Eigen::Vector2d& t, double u, double v) {
  const Eigen::Vector2d V = g.OutputPixelToVirtual({u, v});
  double y = 0.5 * (m.intrinsics().height - 1);
  Eigen::Vector2d p;
  for (int it = 0; it < 50; ++it) {
    Eigen::Quaterniond Rr;
    tl.RealRotation(timing.RowTime(stamp, y), &Rr);
    VirtualToRealPixel<double>(m, Rv, t, Rr, V, &p);
    y = p.y();
  }
  return p;
}

TEST(WarperTest, PureRotationLandsBackgroundOnGroundTruthView) {
  cv::Mat photo = LoadImage("building.jpg");
  ASSERT_FALSE(photo.empty());
  const CameraIntrinsics k = IntrinsicsFromHorizontalFov(640, 480, 1.1);
  const CameraModel m = Model(k);
  const OrientationTimeline tl = ShakeTimeline();
  RollingShutterOptions rs;
  rs.readout_time_s = 0.03;
  const RowTiming timing(rs, k.height);
  const Time stamp = At(0.5);
  RowRotations rows;
  ASSERT_EQ(RowRotations::Build(tl, timing, stamp, 64, &rows),
            QueryResult::kOk);
  // Real frame, rendered row by row with the true timeline.
  const sim::InfiniteBackground bg(photo, 500.0);
  cv::Mat real;
  RenderRows(bg, k, tl, timing, stamp, &real);
  WarpOptions o;
  o.output.crop_ratio = 0.1;
  o.fixed_point_maps = false;
  auto w = MakeWarper(m, o);
  const Eigen::Quaterniond Rv =
      rows.Middle() * ExpSO3(Eigen::Vector3d(0.01, -0.02, 0.015));
  const Eigen::Vector2d t(0.0, 0.0);
  cv::Mat out;
  ASSERT_TRUE(w->Warp(real, Rv, t, rows, &out).ok());

  // 1. Geometry: the warp's per-pixel source vs the exact one.
  cv::Mat mx, my;
  w->FloatMaps(&mx, &my);
  double sum2 = 0.0;
  int n = 0;
  for (int v = 0; v < out.rows; v += 7) {
    for (int u = 0; u < out.cols; u += 7) {
      const Eigen::Vector2d e =
          ExactSource(m, w->output_geometry(), tl, timing, stamp, Rv, t, u, v);
      const double dx = mx.at<float>(v, u) - e.x();
      const double dy = my.at<float>(v, u) - e.y();
      sum2 += dx * dx + dy * dy;
      ++n;
    }
  }
  const double rms = std::sqrt(sum2 / n);
  EXPECT_LT(rms, 0.5) << rms;
  RecordProperty("map_rms_px", std::to_string(rms));

  // 2. Pixels: the ground-truth stabilized view is the virtual camera
  // (global shutter, output intrinsics, rotation Rv) rendered directly.
  cv::Mat truth;
  bg.Render(w->output_geometry().VirtualIntrinsics(t),
            [&](double) { return Rv; }, 480, &truth);
  const double psnr = Psnr(out, truth);
  // Two bilinear resamplings of a detailed photo: compare against the same
  // real frame warped with a deliberately wrong (mid-frame, global shutter)
  // rotation, which must be clearly worse.
  cv::Mat wrong;
  ASSERT_TRUE(w->Warp(real, Rv, t, RowRotations(rows.Middle(), 480), &wrong)
                  .ok());
  const double psnr_wrong = Psnr(wrong, truth);
  EXPECT_GT(psnr, 27.0);
  EXPECT_GT(psnr, psnr_wrong + 3.0) << psnr << " vs " << psnr_wrong;
  RecordProperty("psnr_db", std::to_string(psnr));
}

// x position (sub-pixel) of the dark vertical line nearest `x0` in row y.
double LineX(const cv::Mat& gray, int y, double x0, int half = 10) {
  double s = 0.0, sx = 0.0;
  const int c = static_cast<int>(std::lround(x0));
  for (int x = std::max(0, c - half); x <= std::min(gray.cols - 1, c + half);
       ++x) {
    const double w = 255.0 - gray.at<uchar>(y, x);
    s += w;
    sx += w * x;
  }
  return s > 0 ? sx / s : x0;
}

// RMS residual of tracked line positions from their best straight line.
double Curvature(const cv::Mat& gray, double x_start, int y0, int y1) {
  std::vector<double> ys, xs;
  double x = x_start;
  for (int y = y0; y <= y1; ++y) {
    x = LineX(gray, y, x);
    ys.push_back(y);
    xs.push_back(x);
  }
  cv::Mat A(static_cast<int>(ys.size()), 2, CV_64F), b(A.rows, 1, CV_64F);
  for (int i = 0; i < A.rows; ++i) {
    A.at<double>(i, 0) = ys[i];
    A.at<double>(i, 1) = 1.0;
    b.at<double>(i) = xs[i];
  }
  cv::Mat sol;
  cv::solve(A, b, sol, cv::DECOMP_SVD);
  const cv::Mat r = A * sol - b;
  return std::sqrt(r.dot(r) / A.rows);
}

TEST(WarperTest, RollingShutterStraightensVerticalLines) {
  // Texture: vertical dark lines on white, at infinity.
  cv::Mat tex(1400, 1400, CV_8UC3, cv::Scalar::all(255));
  for (int x = 20; x < tex.cols; x += 90) {
    cv::line(tex, {x, 0}, {x, tex.rows - 1}, cv::Scalar::all(0), 3);
  }
  cv::GaussianBlur(tex, tex, cv::Size(5, 5), 1.0);
  const sim::InfiniteBackground bg(tex, 500.0);
  const CameraIntrinsics k = IntrinsicsFromHorizontalFov(640, 480, 1.1);
  const CameraModel m = Model(k);
  // Yaw shake, 15 Hz, 3 rad/s peak: bends vertical lines in a 30 ms readout.
  OrientationTimeline tl{OrientationTimelineOptions()};
  for (int i = 0; i <= 2000; ++i) {
    const double t = i / 1000.0;
    tl.AddSample({At(t), Eigen::Vector3d(0.0, 3.0 * std::sin(2 * M_PI * 15 * t), 0.0)});
  }
  RollingShutterOptions rs;
  rs.readout_time_s = 0.03;
  const RowTiming timing(rs, k.height);
  const Time stamp = At(0.51);
  cv::Mat real;
  RenderRows(bg, k, tl, timing, stamp, &real);
  RowRotations rows;
  ASSERT_EQ(RowRotations::Build(tl, timing, stamp, 64, &rows), QueryResult::kOk);
  WarpOptions o;
  o.output.crop_ratio = 0.1;
  auto w = MakeWarper(m, o);
  cv::Mat out;
  ASSERT_TRUE(w->Warp(real, rows.Middle(), Eigen::Vector2d::Zero(), rows, &out).ok());
  cv::Mat g_in, g_out;
  cv::cvtColor(real, g_in, cv::COLOR_BGR2GRAY);
  cv::cvtColor(out, g_out, cv::COLOR_BGR2GRAY);
  // Track the line nearest the centre from the middle row's position.
  auto darkest = [](const cv::Mat& g, int y) {
    int best = g.cols / 2;
    for (int x = g.cols / 2 - 45; x <= g.cols / 2 + 45; ++x) {
      if (g.at<uchar>(y, x) < g.at<uchar>(y, best)) best = x;
    }
    return best;
  };
  const double before = Curvature(g_in, darkest(g_in, 40), 40, 440);
  const double after = Curvature(g_out, darkest(g_out, 40), 40, 440);
  RecordProperty("curvature_before_px", std::to_string(before));
  RecordProperty("curvature_after_px", std::to_string(after));
  std::cout << "[ residual line curvature ] before " << before << " px, after "
            << after << " px\n";
  EXPECT_GT(before, 2.0);
  EXPECT_LT(after, 0.25);
}

TEST(WarperTest, UndistortOnlyMatchesOpenCv) {
  CameraIntrinsics k = IntrinsicsFromHorizontalFov(640, 480, 1.3);
  for (DistortionModel model :
       {DistortionModel::kPlumbBob, DistortionModel::kEquidistant}) {
    k.distortion = model;
    k.distortion_coeffs = model == DistortionModel::kPlumbBob
                              ? std::vector<double>{-0.28, 0.09, 0.001, -0.0005, -0.01}
                              : std::vector<double>{0.05, -0.01, 0.004, -0.001};
    const CameraModel m = Model(k);
    WarpOptions o;
    o.output.crop_ratio = 0.0;
    o.fixed_point_maps = false;
    auto w = MakeWarper(m, o);
    const Eigen::Quaterniond R = Eigen::Quaterniond::Identity();
    ASSERT_TRUE(w->ComputeMesh(R, Eigen::Vector2d::Zero(), RowRotations(R, 480)).ok());
    w->BuildMaps();
    cv::Mat mx, my;
    w->FloatMaps(&mx, &my);
    const CameraIntrinsics ko = w->output_geometry().VirtualIntrinsics({0, 0});
    const cv::Matx33d K(k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
    const cv::Matx33d Knew(ko.fx, 0, ko.cx, 0, ko.fy, ko.cy, 0, 0, 1);
    cv::Mat rx, ry;
    if (model == DistortionModel::kPlumbBob) {
      cv::initUndistortRectifyMap(K, k.distortion_coeffs, cv::Matx33d::eye(),
                                  Knew, cv::Size(640, 480), CV_32FC1, rx, ry);
    } else {
      cv::fisheye::initUndistortRectifyMap(K, k.distortion_coeffs,
                                           cv::Matx33d::eye(), Knew,
                                           cv::Size(640, 480), CV_32FC1, rx, ry);
    }
    double worst = 0.0;
    for (int v = 0; v < 480; ++v) {
      for (int u = 0; u < 640; ++u) {
        const double ex = rx.at<float>(v, u), ey = ry.at<float>(v, u);
        if (ex < 0 || ey < 0 || ex > 639 || ey > 479) continue;
        worst = std::max(worst, std::hypot(mx.at<float>(v, u) - ex,
                                           my.at<float>(v, u) - ey));
      }
    }
    EXPECT_LT(worst, 0.5) << "model " << static_cast<int>(model);
    RecordProperty(model == DistortionModel::kPlumbBob ? "plumb_bob_max_px"
                                                       : "equidistant_max_px",
                   std::to_string(worst));
  }
}

TEST(WarperTest, ProtrusionHelperAgreesWithBruteForce) {
  const CameraIntrinsics k = IntrinsicsFromHorizontalFov(320, 240, 1.1);
  const CameraModel m = Model(k);
  const OrientationTimeline tl = ShakeTimeline(2.0);
  RollingShutterOptions rs;
  rs.readout_time_s = 0.025;
  const RowTiming timing(rs, k.height);
  WarpOptions o;
  o.output.crop_ratio = 0.1;
  auto w = MakeWarper(m, o);
  std::mt19937 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  int agree = 0, defined_cases = 0, undefined_cases = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Time stamp = At(0.2 + 0.02 * trial);
    RowRotations rows;
    ASSERT_EQ(RowRotations::Build(tl, timing, stamp, 32, &rows), QueryResult::kOk);
    const Eigen::Quaterniond Rv =
        rows.Middle() * ExpSO3(0.05 * Eigen::Vector3d(n01(rng), n01(rng), 0.5 * n01(rng)));
    const Eigen::Vector2d t = 0.03 * Eigen::Vector2d(n01(rng), n01(rng));
    const ProtrusionReport rep = w->protrusion().Check(Rv, t, rows, 0.0);
    // Brute force: every output pixel, exact fixed point.
    double worst = 0.0;
    for (int v = 0; v < w->output_geometry().height(); ++v) {
      for (int u = 0; u < w->output_geometry().width(); ++u) {
        double row = 120.0;
        Eigen::Vector2d p;
        ASSERT_TRUE(VirtualToRealPixelRS(
            m, Rv, t, rows, w->output_geometry().OutputPixelToVirtual({u, v}),
            30, 1e-6, &p, &row));
        worst = std::max(
            worst, ProtrusionGeometry::Outside<double>(p, 320, 240, 0.0).norm());
      }
    }
    const bool brute_defined = worst == 0.0;
    (brute_defined ? defined_cases : undefined_cases)++;
    // Agreement, up to boundary cases within 0.05 px.
    if (brute_defined == rep.defined || worst < 0.05) ++agree;
    EXPECT_NEAR(rep.max_outside_px, worst, 0.5) << "trial " << trial;
  }
  EXPECT_EQ(agree, 60);
  // The random poses exercise both outcomes.
  EXPECT_GT(defined_cases, 5);
  EXPECT_GT(undefined_cases, 5);
}

TEST(WarperTest, BadPosesAndInputsAreRefused) {
  const CameraIntrinsics k = IntrinsicsFromHorizontalFov(320, 240, 1.1);
  const CameraModel m = Model(k);
  auto w = MakeWarper(m, WarpOptions());
  const RowRotations rows(Eigen::Quaterniond::Identity(), 240);
  Eigen::Quaterniond nan_q(std::nan(""), 0, 0, 0);
  EXPECT_FALSE(w->ComputeMesh(nan_q, Eigen::Vector2d::Zero(), rows).ok());
  EXPECT_FALSE(w->ComputeMesh(Eigen::Quaterniond::Identity(),
                              Eigen::Vector2d(std::nan(""), 0), rows)
                   .ok());
  // Looking backwards: the output maps behind the real camera.
  const Status s = w->ComputeMesh(ExpSO3(Eigen::Vector3d(0, M_PI, 0)),
                                  Eigen::Vector2d::Zero(), rows);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("behind"), std::string::npos);
  // Inputs.
  ASSERT_TRUE(w->ComputeMesh(Eigen::Quaterniond::Identity(),
                             Eigen::Vector2d::Zero(), rows)
                  .ok());
  w->BuildMaps();
  cv::Mat out;
  EXPECT_FALSE(w->Remap(cv::Mat(), &out).ok());
  EXPECT_FALSE(w->Remap(cv::Mat(100, 100, CV_8UC3), &out).ok());
  EXPECT_FALSE(w->Remap(cv::Mat(240, 320, CV_16UC1), &out).ok());
  EXPECT_TRUE(w->Remap(cv::Mat(240, 320, CV_8UC1, cv::Scalar(9)), &out).ok());
  EXPECT_EQ(out.type(), CV_8UC1);
  EXPECT_TRUE(w->Remap(cv::Mat(240, 320, CV_8UC4, cv::Scalar::all(9)), &out).ok());
  // Row rotations of another size.
  EXPECT_FALSE(w->ComputeMesh(Eigen::Quaterniond::Identity(),
                              Eigen::Vector2d::Zero(),
                              RowRotations(Eigen::Quaterniond::Identity(), 100))
                   .ok());
  WarpOptions bad;
  bad.output.crop_ratio = 0.6;
  std::unique_ptr<Warper> w2;
  EXPECT_FALSE(Warper::Create(m, bad, &w2).ok());
}

TEST(WarperTest, ThreadCountDoesNotChangeOutput) {
  cv::Mat photo;
  cv::resize(LoadImage("leuvenA.jpg"), photo, cv::Size(640, 480));
  const CameraIntrinsics k = IntrinsicsFromHorizontalFov(640, 480, 1.1);
  const CameraModel m = Model(k);
  const Eigen::Quaterniond Rr = ExpSO3(Eigen::Vector3d(0.01, 0.02, 0.0));
  const Eigen::Quaterniond Rv = ExpSO3(Eigen::Vector3d(0.02, 0.0, 0.01));
  cv::Mat out1, out2;
  WarpOptions o;
  o.num_threads = 1;
  ASSERT_TRUE(MakeWarper(m, o)->Warp(photo, Rv, {0.01, 0}, RowRotations(Rr, 480), &out1).ok());
  o.num_threads = 2;
  ASSERT_TRUE(MakeWarper(m, o)->Warp(photo, Rv, {0.01, 0}, RowRotations(Rr, 480), &out2).ok());
  EXPECT_EQ(cv::norm(out1, out2, cv::NORM_INF), 0.0);
  cv::setNumThreads(-1);
}

// Direct sampling (SampleMesh) against cv::remap with the Warper's own
// fixed-point maps: bit for bit, for 1 to 4 channels, an odd size, rolling
// shutter, lens distortion and poses that show the black border.
TEST(WarperTest, DirectSamplingIsRemapBitForBit) {
  cv::Mat photo = LoadImage("leuvenA.jpg");
  const OrientationTimeline tl = ShakeTimeline(6.0);
  RollingShutterOptions rs;
  rs.readout_time_s = 0.03;
  int border_frames = 0;
  for (const cv::Size size : {cv::Size(640, 480), cv::Size(333, 251)}) {
    cv::Mat bgr;
    cv::resize(photo, bgr, size, 0, 0, cv::INTER_AREA);
    std::vector<cv::Mat> inputs(4);
    cv::cvtColor(bgr, inputs[0], cv::COLOR_BGR2GRAY);
    cv::Mat two[] = {inputs[0], 255 - inputs[0]};
    cv::merge(two, 2, inputs[1]);
    inputs[2] = bgr;
    cv::cvtColor(bgr, inputs[3], cv::COLOR_BGR2BGRA);
    for (bool distorted : {false, true}) {
      CameraIntrinsics k = IntrinsicsFromHorizontalFov(size.width, size.height, 1.2);
      if (distorted) {
        k.distortion = DistortionModel::kPlumbBob;
        k.distortion_coeffs = {-0.2, 0.05, 0.001, -0.0005, 0.0};
      }
      const CameraModel m = Model(k);
      RowRotations rows;
      RowRotations::Build(tl, RowTiming(rs, size.height), At(0.4), 32, &rows);
      for (const Eigen::Vector3d& w :
           {Eigen::Vector3d(0.004, -0.01, 0.003), Eigen::Vector3d(0.05, 0.3, -0.2)}) {
        const Eigen::Quaterniond Rv = rows.Middle() * ExpSO3(w);
        WarpOptions direct, maps;
        maps.direct_sampling = false;
        auto a = MakeWarper(m, direct);
        auto b = MakeWarper(m, maps);
        for (int cn = 1; cn <= 4; ++cn) {
          cv::Mat out_a, out_b;
          ASSERT_TRUE(a->Warp(inputs[cn - 1], Rv, {0.01, -0.02}, rows, &out_a).ok());
          ASSERT_TRUE(b->Warp(inputs[cn - 1], Rv, {0.01, -0.02}, rows, &out_b).ok());
          ASSERT_EQ(out_a.type(), out_b.type());
          EXPECT_EQ(cv::norm(out_a, out_b, cv::NORM_INF), 0.0)
              << size << " distorted " << distorted << " channels " << cn << " pose "
              << w.transpose();
          if (cn == 1 && cv::countNonZero(out_a == 0) > 1000) ++border_frames;
        }
      }
    }
  }
  EXPECT_GE(border_frames, 2);  // the large pose shows the black border
}

}  // namespace
}  // namespace steadiface

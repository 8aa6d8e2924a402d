// The view module: the output geometry at another crop ratio, the margin a
// pose uses (CropNeed), the dynamic crop's rate-bounded controller and the
// shake path it sizes the crop by, against closed forms.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/common/so3.h"
#include "steadiface_core/view/crop_need.h"
#include "steadiface_core/view/dynamic_crop.h"
#include "steadiface_core/view/shake_path.h"
#include "steadiface_core/camera/output_geometry.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_core/warp/protrusion.h"

namespace steadiface {
namespace {

CameraModel Model() {
  CameraModel m;
  EXPECT_TRUE(CameraModel::Create(IntrinsicsFromHorizontalFov(640, 360, 1.1),
                                  CameraModelOptions(), &m)
                  .ok());
  return m;
}

OutputGeometry Geometry(const CameraModel& m, double r) {
  OutputOptions o;
  o.crop_ratio = r;
  OutputGeometry g;
  EXPECT_TRUE(OutputGeometry::Create(m, o, &g).ok());
  return g;
}

TEST(OutputGeometryTest, AnotherCropRatioIsTheWindowScaledAboutItsCentre) {
  const CameraModel m = Model();
  const OutputGeometry fixed = Geometry(m, 0.15);
  const OutputGeometry wide = fixed.WithCropRatio(0.05);
  const OutputGeometry direct = Geometry(m, 0.05);
  EXPECT_EQ(wide.width(), 640);
  EXPECT_EQ(wide.height(), 360);
  EXPECT_DOUBLE_EQ(wide.crop_ratio(), 0.05);
  // Same as building it at 0.05 outright.
  for (const Eigen::Vector2d uv :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(639, 359),
        Eigen::Vector2d(100.5, 17.0)}) {
    EXPECT_NEAR(
        (wide.OutputPixelToVirtual(uv) - direct.OutputPixelToVirtual(uv))
            .norm(),
        0.0, 1e-12);
  }
  // The focal length in output pixels scales with the kept width:
  // (1 - 2 * 0.15) / (1 - 2 * 0.05); the centre stays.
  const CameraIntrinsics kf = fixed.VirtualIntrinsics(Eigen::Vector2d::Zero());
  const CameraIntrinsics kw = wide.VirtualIntrinsics(Eigen::Vector2d::Zero());
  EXPECT_NEAR(kw.fx / kf.fx, 0.7 / 0.9, 1e-12);
  EXPECT_NEAR(kw.fy / kf.fy, 0.7 / 0.9, 1e-12);
  EXPECT_DOUBLE_EQ(kw.cx, kf.cx);
  EXPECT_DOUBLE_EQ(kw.cy, kf.cy);
  // Out of range: clamped.
  EXPECT_DOUBLE_EQ(fixed.WithCropRatio(0.9).crop_ratio(), 0.4);
  EXPECT_DOUBLE_EQ(fixed.WithCropRatio(-1.0).crop_ratio(), 0.0);
}

TEST(CropNeedTest, APrincipalOffsetNeedsItsOwnSizeOfMargin) {
  const CameraModel m = Model();
  const OutputGeometry g = Geometry(m, 0.15);
  const RowRotations rows(Eigen::Quaterniond::Identity(), 360);
  const Eigen::Quaterniond I = Eigen::Quaterniond::Identity();
  // The identity pose is defined for the whole frame, to within the half
  // pixel between the principal point's and the pixel centres' conventions.
  EXPECT_LE(CropNeed(m, g, I, Eigen::Vector2d::Zero(), rows), 1.0 / 640);
  // An offset t moves the window by t (normalized, fractions of the width):
  // the far edge's outer pixel centres, half an output pixel inside the
  // window, reach the frame's last pixel centre at r = t (to within one
  // input pixel, and the bisection's 0.4 / 2^12).
  for (double tx : {0.02, 0.07, 0.12}) {
    const double need =
        CropNeed(m, g, I, Eigen::Vector2d(tx, 0.0), rows, 8, 12);
    EXPECT_LE(need, tx + 1e-3) << tx;
    EXPECT_GE(need, tx - 1.0 / 640 - 1e-3) << tx;
  }
  // Vertically the margin is in the same units, fractions of the width.
  const double ty = 0.05;
  const double need_y =
      CropNeed(m, g, I, Eigen::Vector2d(0.0, ty), rows, 8, 12);
  const double extent_y = 360.0 / 640.0;  // fx = fy here
  EXPECT_NEAR(need_y * extent_y, ty, 1.5 / 640 + 1e-3);
}

TEST(CropNeedTest, AYawNeedsAtLeastTheClosedFormSideMarginAndIsDefinedThere) {
  const CameraModel m = Model();
  const OutputGeometry g = Geometry(m, 0.15);
  const RowRotations rows(Eigen::Quaterniond::Identity(), 360);
  const double f = m.virtual_focal();  // normalized: fractions of the width
  for (double yaw : {0.02, 0.06, 0.1}) {
    const Eigen::Quaterniond R_v(
        Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()));
    const double need =
        CropNeed(m, g, R_v, Eigen::Vector2d::Zero(), rows, 8, 12);
    // The middle row's edge: the ray at atan((0.5 - r) / f) turned by the
    // yaw must stay within atan(0.5 / f).
    const double side = 0.5 - f * std::tan(std::atan(0.5 / f) - yaw);
    EXPECT_GE(need, side - 1.0 / 640 - 1e-3) << yaw;
    EXPECT_LT(need, side + 0.05) << yaw;  // the corners ask for a little more
    const ProtrusionGeometry at_need(m, g.WithCropRatio(need), 8);
    EXPECT_TRUE(at_need.Check(R_v, Eigen::Vector2d::Zero(), rows, 0.0).defined)
        << yaw;
    const ProtrusionGeometry below(m, g.WithCropRatio(need - 0.002), 8);
    EXPECT_FALSE(below.Check(R_v, Eigen::Vector2d::Zero(), rows, 0.0).defined)
        << yaw;
  }
}

DynamicCropOptions Dynamic() {
  DynamicCropOptions o;
  o.mode = CropMode::kDynamic;
  return o;
}

TEST(DynamicCropTest, OptionsAreChecked) {
  EXPECT_TRUE(ValidateDynamicCropOptions(Dynamic()).ok());
  DynamicCropOptions o = Dynamic();
  o.widest_crop_ratio = 0.5;
  EXPECT_FALSE(ValidateDynamicCropOptions(o).ok());
  o = Dynamic();
  o.headroom = 0.5;
  EXPECT_FALSE(ValidateDynamicCropOptions(o).ok());
  o = Dynamic();
  o.max_tighten_rate = NAN;
  EXPECT_FALSE(ValidateDynamicCropOptions(o).ok());
  // A widest view narrower than the fixed crop: the fixed crop.
  o = Dynamic();
  o.widest_crop_ratio = 0.2;
  DynamicCrop narrow(o, 0.15);
  EXPECT_EQ(narrow.crop_ratio(), 0.15);
  for (int i = 0; i < 30; ++i) narrow.Update(i / 30.0, 0.0, 0.0);
  EXPECT_EQ(narrow.crop_ratio(), 0.15);
  CropMode mode;
  EXPECT_TRUE(ParseCropMode("dynamic", &mode).ok());
  EXPECT_EQ(mode, CropMode::kDynamic);
  EXPECT_FALSE(ParseCropMode("zoom", &mode).ok());
  EXPECT_STREQ(CropModeName(CropMode::kFixed), "fixed");
}

// The composite's matte and plate do not follow the crop's zoom: valid
// options, named a conflict (the node WARNs, steadiface_bag prints it);
// every other pairing of warp mode and crop is none.
TEST(DynamicCropTest, TheCompositeWithTheDynamicCropIsTheOneConflict) {
  for (WarpMode w : {WarpMode::kGlobal, WarpMode::kLayered, WarpMode::kComposite}) {
    for (CropMode c : {CropMode::kFixed, CropMode::kDynamic}) {
      PipelineOptions o;
      o.warp.mode = w;
      o.crop.mode = c;
      EXPECT_TRUE(ValidatePipelineOptions(o).ok());
      const std::string conflict = OptionsConflict(o);
      if (w == WarpMode::kComposite && c == CropMode::kDynamic) {
        EXPECT_NE(conflict.find("output/crop fixed"), std::string::npos) << conflict;
      } else {
        EXPECT_EQ(conflict, "") << static_cast<int>(w) << " " << static_cast<int>(c);
      }
    }
  }
}

TEST(DynamicCropTest, TheFixedCropNeverMoves) {
  DynamicCropOptions o;  // kFixed
  DynamicCrop crop(o, 0.15);
  for (int i = 0; i < 100; ++i) {
    const CropReport r = crop.Update(i / 30.0, 0.01 * (i % 7), 0.3);
    EXPECT_EQ(r.crop_ratio, 0.15);
    EXPECT_FALSE(r.dynamic);
  }
  EXPECT_EQ(crop.crop_ratio(), 0.15);
}

// Runs `frames` frames at 30 fps with needs given per frame; returns the
// crop ratios the frames were made with.
std::vector<double> RunFrames(DynamicCrop* crop, int frames, double shake,
                              double solved, double t0 = 0.0) {
  std::vector<double> r;
  for (int i = 0; i < frames; ++i)
    r.push_back(crop->Update(t0 + i / 30.0, shake, solved).crop_ratio);
  return r;
}

void ExpectBounded(const std::vector<double>& r, const DynamicCropOptions& o) {
  const double dt = 1.0 / 30.0;
  const double v = std::max(o.max_widen_rate, o.max_tighten_rate) * dt;
  const double a = std::max(o.max_widen_accel, o.max_tighten_accel) * dt * dt;
  for (size_t i = 1; i < r.size(); ++i) {
    EXPECT_LE(std::abs(r[i] - r[i - 1]), v + 1e-12) << i;
    // The second difference: at most a dt^2, and one more when the crop
    // arrives at its target or a bound (it stops there).
    if (i >= 2)
      EXPECT_LE(std::abs(r[i] - 2 * r[i - 1] + r[i - 2]),
                2 * a + v * 1e-9 + 1e-12)
          << i;
  }
}

TEST(
    DynamicCropTest,
    StartsWideAndTightensToHeadroomTimesTheShakeWithBoundedRateAndAcceleration) {
  const DynamicCropOptions o = Dynamic();
  DynamicCrop crop(o, 0.15);
  EXPECT_EQ(crop.crop_ratio(), o.widest_crop_ratio);
  const std::vector<double> r = RunFrames(&crop, 90, 0.05, 0.0);
  ExpectBounded(r, o);
  // headroom 1.5 x 0.05 + extra 0.01 = 0.085, reached within 3 s
  // (0.055 at 0.15/s after 0.5 s of acceleration: under a second).
  EXPECT_NEAR(crop.crop_ratio(), 1.5 * 0.05 + 0.01, 1e-9);
  // No overshoot beyond its last step's rounding (1e-4: 0.06 px at 640).
  for (size_t i = 1; i < r.size(); ++i) EXPECT_GE(r[i], r[i - 1] - 1e-4) << i;
  for (double x : r) EXPECT_LE(x, 0.085 + 1e-4);
}

TEST(DynamicCropTest, ASolvedPoseAtTheEdgeTightensItUntilItFits) {
  DynamicCrop crop(Dynamic(), 0.15);
  // The solve asks for what the crop gives (E_p holding it at the edge):
  // every frame asks for `extra` more, until the tightest.
  double t = 0.0;
  for (int i = 0; i < 150; ++i, t += 1.0 / 30)
    crop.Update(t, 0.0, crop.crop_ratio());
  EXPECT_NEAR(crop.crop_ratio(), 0.15, 1e-9);
}

TEST(DynamicCropTest, WidensOnlyAfterTheMemoryAndSlowly) {
  DynamicCropOptions o = Dynamic();
  o.start_wide = false;
  DynamicCrop crop(o, 0.15);
  EXPECT_EQ(crop.crop_ratio(), 0.15);
  std::vector<double> r =
      RunFrames(&crop, 30, 0.1, 0.0);  // 0.16: held at the tightest
  const double held = crop.crop_ratio();
  EXPECT_EQ(held, 0.15);
  // Calm from t = 1 s: nothing changes until the need is forgotten (3 s).
  std::vector<double> calm = RunFrames(&crop, 300, 0.0, 0.0, 1.0);
  for (int i = 0; i < 85; ++i) EXPECT_NEAR(calm[i], held, 1e-9) << i;
  // Then slowly: 7 s at most 0.002/s^2 up to 0.01/s, 0.045 at most.
  EXPECT_LT(calm.back(), held - 0.03);
  EXPECT_GT(calm.back(), held - 0.046);
  r.insert(r.end(), calm.begin(), calm.end());
  ExpectBounded(r, o);
  // Never faster than max_widen_rate.
  for (size_t i = 1; i < calm.size(); ++i) {
    EXPECT_GE(calm[i] - calm[i - 1], -o.max_widen_rate / 30.0 - 1e-12);
  }
  // After a long calm, the widest.
  RunFrames(&crop, 900, 0.0, 0.0, 11.0);
  EXPECT_NEAR(crop.crop_ratio(), o.widest_crop_ratio, 1e-9);
}

TEST(DynamicCropTest, NonFiniteNeedsAndTimesChangeNothing) {
  DynamicCrop crop(Dynamic(), 0.15);
  const double r0 = crop.crop_ratio();
  crop.Update(NAN, 0.1, 0.1);
  crop.Update(0.0, NAN, 0.0);
  crop.Update(1.0 / 30, INFINITY, 0.0);
  EXPECT_EQ(crop.crop_ratio(), r0);
  EXPECT_TRUE(std::isfinite(crop.crop_ratio()));
}

TEST(ShakePathTest, FollowsAPanWithoutLagAndRemovesAFastShake) {
  const double fps = 30.0;
  ShakePath path(0.7);
  // A 0.5 rad/s pan about y with a 6 Hz, 0.01 rad shake about x.
  double worst_late = 0.0;
  for (int i = 0; i < 300; ++i) {
    const double t = i / fps;
    const Eigen::Quaterniond R_pan(
        Eigen::AngleAxisd(0.5 * t, Eigen::Vector3d::UnitY()));
    const Eigen::Quaterniond R_r =
        R_pan *
        Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * std::sin(2 * M_PI * 6 * t),
                                             Eigen::Vector3d::UnitX()));
    const Eigen::Quaterniond& P = path.Update(R_r, i == 0 ? 0.0 : 1.0 / fps);
    if (t > 4.0) {
      // The path is the pan, give or take a fraction of the shake.
      worst_late = std::max(worst_late, LogSO3(R_pan.conjugate() * P).norm());
    }
  }
  EXPECT_LT(worst_late, 0.004);
}

TEST(ShakePathTest, FollowsASlowTurn) {
  ShakePath path(0.7);
  double worst = 0.0;
  for (int i = 0; i < 600; ++i) {
    const double t = i / 30.0;
    const Eigen::Quaterniond R_r(Eigen::AngleAxisd(
        0.2 * std::sin(2 * M_PI * 0.05 * t), Eigen::Vector3d::UnitZ()));
    const Eigen::Quaterniond& P = path.Update(R_r, i == 0 ? 0.0 : 1.0 / 30);
    if (t > 2.0) worst = std::max(worst, LogSO3(R_r.conjugate() * P).norm());
  }
  // 0.05 Hz of 0.2 rad, far below 0.7 Hz: once the start (at rest, while
  // the turn already moves) has settled, within its acceleration over k^2,
  // 0.0197 / 19.3 = 1 mrad.
  EXPECT_LT(worst, 0.0015);
}

}  // namespace
}  // namespace steadiface

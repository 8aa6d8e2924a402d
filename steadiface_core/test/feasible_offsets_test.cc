// eval::FeasibleOffsets, what the crop margin allows per frame
// (scripts/analysis/crop_bound.py --feasible): the margin's box in closed form, and
// a brute force over every boundary pixel under a rolling-shutter yaw.
#include "steadiface_core/eval/feasible_offsets.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "steadiface_core/common/so3.h"
#include "steadiface_core/warp/warp_geometry.h"
#include "test_util.h"

namespace steadiface {
namespace {

// The largest shift along `dir` [input px] for which every output boundary
// pixel (all of them, not ProtrusionGeometry's samples) lands inside the
// real frame, each on its own row (the exact fixed point), by bisection: the
// brute force of WarperTest.ProtrusionHelperAgreesWithBruteForce.
double BruteForceRoom(const CameraModel& m, const OutputGeometry& og, const RowRotations& rows,
                      const Eigen::Vector2d& dir) {
  const CameraIntrinsics& k = m.intrinsics();
  auto defined = [&](double s_px) {
    const Eigen::Vector2d t = s_px * dir / k.width;  // normalized
    const int w = og.width(), h = og.height();
    for (int i = 0; i < 2 * (w + h); ++i) {
      const Eigen::Vector2d uv = i < w           ? Eigen::Vector2d(i, 0)
                                 : i < 2 * w     ? Eigen::Vector2d(i - w, h - 1)
                                 : i < 2 * w + h ? Eigen::Vector2d(0, i - 2 * w)
                                                 : Eigen::Vector2d(w - 1, i - 2 * w - h);
      double row = 0.5 * (k.height - 1);
      Eigen::Vector2d p;
      if (!VirtualToRealPixelRS(m, rows.Middle(), t, rows, og.OutputPixelToVirtual(uv), 30, 1e-6,
                                &p, &row) ||
          ProtrusionGeometry::Outside<double>(p, k.width, k.height, 0.0).norm() > 0.0) {
        return false;
      }
    }
    return true;
  };
  double lo = 0.0, hi = k.width;
  while (hi - lo > 0.01) (defined(0.5 * (lo + hi)) ? lo : hi) = 0.5 * (lo + hi);
  return lo;
}

// The 640 x 360 test camera and its output at the default 15 % crop.
class FeasibleOffsetsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    OutputOptions oo;
    oo.crop_ratio = 0.15;
    ASSERT_TRUE(OutputGeometry::Create(m, oo, &og).ok());
  }
  const CameraModel m = testing_util::Model640x360();
  OutputGeometry og;
};

// Global shutter, no rotation: the offsets a 15 % crop allows are the box of
// its margin, r * W by r * H per side (to the half pixel the outer pixel
// centres leave). With a 30 ms readout during a 1 rad/s yaw the window's
// rows are skewed, which the x room loses; there the radii match a brute
// force over every boundary pixel.
TEST_F(FeasibleOffsetsTest, TheMarginsBoxAndWhatRollingShutterSkewTakes) {
  const eval::FeasibleOffsets feasible(m, og, 8);
  const Eigen::Quaterniond I = Eigen::Quaterniond::Identity();
  const std::vector<double> box = feasible.Radii(RowRotations(I, 360), I, 8);
  ASSERT_EQ(box.size(), 8u);
  const double mx = 0.15 * 640, my = 0.15 * 360;  // 96 and 54 px
  EXPECT_NEAR(box[0], mx, 1.0);                   // +x
  EXPECT_NEAR(box[4], mx, 1.0);                   // -x
  EXPECT_NEAR(box[2], my, 1.0);                   // +y
  EXPECT_NEAR(box[6], my, 1.0);                   // -y
  EXPECT_NEAR(box[1], my * std::sqrt(2.0), 1.5);  // the corner binds on y
  // Rolling shutter: row y read at readout * (y / 359 - 1/2) from the middle.
  const double readout = 0.03, rate = 1.0;
  std::vector<Eigen::Quaterniond> table;
  for (int k = 0; k < 32; ++k) {
    table.push_back(ExpSO3(Eigen::Vector3d(0.0, rate * readout * (k / 31.0 - 0.5), 0.0)));
  }
  const RowRotations rows = RowRotations::FromTable(table, 360);
  const std::vector<double> skewed = feasible.Radii(rows, rows.Middle(), 8);
  for (int d : {0, 2, 4, 6}) {
    const double a = 2.0 * M_PI * d / 8;
    EXPECT_NEAR(skewed[d], BruteForceRoom(m, og, rows, Eigen::Vector2d(std::cos(a), std::sin(a))),
                0.5)
        << "direction " << d;
  }
  // At least the skew at the view centre is lost: f * rate * readout over
  // the crop's 252 rows.
  const double skew_px = 320.0 / std::tan(0.6) * rate * readout * 251.0 / 359.0;
  EXPECT_LT(skewed[0] + skewed[4], 2.0 * mx - skew_px);
}

// A window that also rolls (crop_bound.py --feasible-roll): on a still
// global-shutter frame a roll is an in-plane rotation about the principal
// point. A pixel 100 px right of it moves by (100 (cos a - 1), 100 sin a);
// the rolled 448 x 252 px window's extent is then a cos + b sin per axis, so
// its room is the frame's half size less that, in closed form.
TEST_F(FeasibleOffsetsTest,
       ARolledWindowIsTheBoxRotatedAboutThePrincipalPoint) {
  const eval::FeasibleOffsets feasible(m, og, 8);
  const Eigen::Quaterniond I = Eigen::Quaterniond::Identity();
  const RowRotations still(I, 360);
  const CameraIntrinsics& k = m.intrinsics();
  const double roll = 0.05;
  Eigen::Vector2d shift;
  ASSERT_TRUE(feasible.RollShift(still, I, roll,
                                 Eigen::Vector2d(k.cx + 100.0, k.cy), &shift));
  EXPECT_NEAR(shift.x(), 100.0 * (std::cos(roll) - 1.0), 1e-6);
  EXPECT_NEAR(shift.y(), 100.0 * std::sin(roll), 1e-6);
  ASSERT_TRUE(
      feasible.RollShift(still, I, roll, Eigen::Vector2d(k.cx, k.cy), &shift));
  EXPECT_NEAR(shift.norm(), 0.0, 1e-9);
  // Roll 0 is the unrolled set.
  EXPECT_EQ(feasible.Radii(still, eval::FeasibleOffsets::Rolled(I, 0.0), 8),
            feasible.Radii(still, I, 8));
  const std::vector<double> rolled =
      feasible.Radii(still, eval::FeasibleOffsets::Rolled(I, roll), 8);
  const double a = 0.35 * 640, b = 0.35 * 360;  // the window's half size [px]
  const double room_x =
      320.0 - (a * std::cos(roll) + b * std::sin(roll));  // 89.98 px
  const double room_y =
      180.0 - (a * std::sin(roll) + b * std::cos(roll));  // 42.96 px
  EXPECT_NEAR(rolled[0], room_x, 1.0);
  EXPECT_NEAR(rolled[4], room_x, 1.0);
  EXPECT_NEAR(rolled[2], room_y, 1.0);
  EXPECT_NEAR(rolled[6], room_y, 1.0);
}

}  // namespace
}  // namespace steadiface

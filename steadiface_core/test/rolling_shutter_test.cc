#include "steadiface_core/camera/rolling_shutter.h"

#include <gtest/gtest.h>

#include "steadiface_core/common/so3.h"
#include "steadiface_core/gyro/row_rotations.h"

namespace steadiface {
namespace {

Time At(double seconds) { return Time(FromSeconds(seconds)); }

TEST(RowTimingTest, StampConventions) {
  RollingShutterOptions o;
  o.readout_time_s = 0.03;
  const int h = 721;  // rows 0..720, middle row 360
  o.stamp = StampConvention::kFirstRow;
  RowTiming first(o, h);
  EXPECT_EQ(first.RowTime(At(5.0), 0.0), At(5.0));
  EXPECT_EQ(first.RowTime(At(5.0), 360.0), At(5.015));
  EXPECT_EQ(first.LastRowTime(At(5.0)), At(5.03));
  o.stamp = StampConvention::kMiddleRow;
  RowTiming mid(o, h);
  EXPECT_EQ(mid.FirstRowTime(At(5.0)), At(4.985));
  EXPECT_EQ(mid.RowTime(At(5.0), 360.0), At(5.0));
  EXPECT_EQ(mid.LastRowTime(At(5.0)), At(5.015));
  o.stamp = StampConvention::kLastRow;
  RowTiming last(o, h);
  EXPECT_EQ(last.LastRowTime(At(5.0)), At(5.0));
  EXPECT_EQ(last.FirstRowTime(At(5.0)), At(4.97));
  o.stamp = StampConvention::kFirstRow;
  o.row_time_offset_s = 0.004;  // mid-exposure of a 8 ms exposure
  RowTiming offset(o, h);
  EXPECT_EQ(offset.FirstRowTime(At(5.0)), At(5.004));
}

TEST(RowTimingTest, GlobalShutterRowsShareTheStamp) {
  RollingShutterOptions o;
  RowTiming g(o, 480);
  EXPECT_EQ(g.FirstRowTime(At(2.0)), g.LastRowTime(At(2.0)));
}

TEST(RowTimingTest, PerRowRealRotation) {
  // Constant rate: rows differ by exactly Exp(omega * readout * dy / (H-1)).
  OrientationTimeline tl{OrientationTimelineOptions()};
  const Eigen::Vector3d w(0.5, -1.0, 0.2);
  for (int i = 0; i <= 200; ++i) tl.AddSample({At(i / 200.0), w});
  RollingShutterOptions o;
  o.readout_time_s = 0.02;
  o.stamp = StampConvention::kMiddleRow;
  RowTiming timing(o, 1001);
  Eigen::Quaterniond top, bottom, mid;
  ASSERT_EQ(RealRotationAtRow(tl, timing, At(0.5), 0.0, &top),
            QueryResult::kOk);
  ASSERT_EQ(RealRotationAtRow(tl, timing, At(0.5), 1000.0, &bottom),
            QueryResult::kOk);
  ASSERT_EQ(RealRotationAtRow(tl, timing, At(0.5), 500.0, &mid),
            QueryResult::kOk);
  // R_r = q_wc^-1 so q_wc(bottom) = q_wc(top) * Exp(w * 0.02).
  const Eigen::Quaterniond rel = top * bottom.conjugate();
  EXPECT_NEAR(AngleBetween(rel, ExpSO3(w * 0.02)), 0.0, 1e-12);
  EXPECT_NEAR(AngleBetween(mid, ExpSO3(w * 0.5).conjugate()), 0.0, 1e-12);
}

TEST(RowTimingTest, NonFiniteRowGivesTheMiddleRow) {
  // Found by fuzz_imu: a NaN row was cast to an index.
  const RowRotations rows = RowRotations::FromTable(
      {ExpSO3(Eigen::Vector3d(0.1, 0, 0)), ExpSO3(Eigen::Vector3d(0.2, 0, 0)),
       ExpSO3(Eigen::Vector3d(0.3, 0, 0))},
      101);
  EXPECT_NEAR(AngleBetween(rows.At(NAN), rows.At(50.0)), 0.0, 1e-12);
  EXPECT_NEAR(AngleBetween(rows.At(INFINITY), rows.At(50.0)), 0.0, 1e-12);
  EXPECT_NEAR(AngleBetween(rows.At(-5.0), rows.At(0.0)), 0.0, 1e-12);
}

TEST(RowTimingTest, Validation) {
  RollingShutterOptions o;
  EXPECT_TRUE(ValidateRollingShutterOptions(o).ok());
  o.readout_time_s = -0.01;
  const Status s = ValidateRollingShutterOptions(o);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("readout_time"), std::string::npos);
}

}  // namespace
}  // namespace steadiface

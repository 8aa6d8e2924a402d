#include "steadiface_ros/time_conversion.h"

#include <gtest/gtest.h>

namespace steadiface_ros {
namespace {

TEST(TimeConversionTest, RoundTripIsExactForEpochStamps) {
  // 2026 epoch stamp with nanosecond detail (a double in seconds would lose
  // the last digits).
  const ros::Time t(1795000000, 123456789);
  const steadiface::Time core = ToCoreTime(t);
  EXPECT_EQ(steadiface::ToNanoseconds(core), 1795000000123456789LL);
  EXPECT_EQ(ToRosTime(core), t);
}

TEST(TimeConversionTest, DifferencesArePreserved) {
  const ros::Time a(100, 999999999), b(101, 1);
  EXPECT_EQ((ToCoreTime(b) - ToCoreTime(a)).count(), 2);
  EXPECT_EQ(ToCoreDuration(ros::Duration(-1, 500000000)).count(), -500000000);
}

TEST(TimeConversionTest, NegativeCoreTimeClampsToZero) {
  EXPECT_EQ(ToRosTime(steadiface::FromNanoseconds(-5)), ros::Time(0, 0));
  EXPECT_EQ(ToRosTime(steadiface::FromNanoseconds(0)), ros::Time(0, 0));
}

}  // namespace
}  // namespace steadiface_ros

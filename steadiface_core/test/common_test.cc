// common/: the jitter measure (HighPassRms) on signals whose answer is
// known, time conversion and Status.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "steadiface_core/common/high_pass_rms.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/common/time.h"

namespace steadiface {
namespace {

// 90 samples at 30 fps: a 5 Hz sine of amplitude a falls on a DFT bin.
std::vector<Eigen::Vector2d> Signal(double a, double hz, double slope) {
  std::vector<Eigen::Vector2d> x;
  for (int i = 0; i < 90; ++i) {
    const double t = i / 30.0;
    x.emplace_back(a * std::sin(2 * M_PI * hz * t) + slope * t, 0.0);
  }
  return x;
}

TEST(HighPassRmsTest, KeepsJitterAboveTheCutoffAndDropsALinearTrend) {
  // A sine's RMS is a / sqrt(2), less the little of it the removed
  // least-squares trend takes (0.2 % over 15 cycles); a linear trend adds
  // nothing, and alone scores 0.
  const double sine = HighPassRms(Signal(4.0, 5.0, 0.0), 30.0, 0.5);
  EXPECT_NEAR(sine, 4.0 / std::sqrt(2.0), 0.005 * 4.0 / std::sqrt(2.0));
  EXPECT_NEAR(HighPassRms(Signal(4.0, 5.0, 7.0), 30.0, 0.5), sine, 1e-9);
  EXPECT_NEAR(HighPassRms(Signal(0.0, 5.0, 7.0), 30.0, 0.5), 0.0, 1e-9);
  // Twice the amplitude, twice the jitter; under 4 samples, 0.
  EXPECT_NEAR(HighPassRms(Signal(8.0, 5.0, 0.0), 30.0, 0.5), 2.0 * sine, 1e-9);
  EXPECT_EQ(HighPassRms(std::vector<Eigen::Vector2d>(3, Eigen::Vector2d(1, 2)), 30.0, 0.5), 0.0);
}

TEST(TimeTest, SecondsRoundTripToTheNanosecond) {
  const Time t = FromNanoseconds(1700000000123456789LL);
  EXPECT_EQ(ToNanoseconds(t + FromSeconds(0.5)) - ToNanoseconds(t), 500000000LL);
  EXPECT_NEAR(ToSeconds(FromSeconds(-0.0123)), -0.0123, 1e-12);
}

TEST(StatusTest, CarriesTheMessageOfAnError) {
  EXPECT_TRUE(Status::Ok().ok());
  const Status e = Status::Error("face: no model");
  EXPECT_FALSE(e.ok());
  EXPECT_EQ(e.message(), "face: no model");
}

}  // namespace
}  // namespace steadiface

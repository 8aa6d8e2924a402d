// The slow-motion filters against closed forms: ramps, slow and fast
// sinusoids, restarts.
#include <algorithm>
#include <cmath>
#include <iostream>

#include <gtest/gtest.h>

#include "steadiface_core/common/tracking_lowpass.h"

namespace steadiface {
namespace {

constexpr double kDt = 1.0 / 30;

// Steady-state amplitude of the filter's output for x = A sin(2 pi f t):
// the largest |output| over the last full period of 3 periods (at least
// 12 s).
template <typename Filter>
double OutputAmplitude(Filter* filter, double f, double A) {
  const double T = std::max(12.0, 3.0 / f);
  const int n = static_cast<int>(T / kDt);
  double peak = 0.0;
  for (int i = 0; i < n; ++i) {
    const double t = i * kDt;
    const Eigen::Vector2d x(A * std::sin(2 * M_PI * f * t), 0.0);
    const Eigen::Vector2d& y = filter->Update(x, i ? kDt : 0.0);
    if (t > T - 1.0 / f) peak = std::max(peak, std::abs(y.x()));
  }
  return peak;
}

// A subject walking across the view at 180 px/s: the filter starts at its
// first position with an unknown velocity and is on the ramp within a
// fraction of a second, then follows it without lag.
TEST(SlowMotionFilterTest, PicksUpARampWithinAFewFramesAndFollowsItWithoutLag) {
  SlowMotionFilter f(0.2);
  const Eigen::Vector2d v(180.0, -30.0);  // px/s
  double error_at_half_second = 0.0, worst_after_one_second = 0.0, worst_after_two = 0.0;
  for (int i = 0; i <= 90; ++i) {
    const Eigen::Vector2d x = Eigen::Vector2d(100, 200) + v * (i * kDt);
    const double e = (f.Update(x, i ? kDt : 0.0) - x).norm();
    if (i == 15) error_at_half_second = e;
    if (i >= 30) worst_after_one_second = std::max(worst_after_one_second, e);
    if (i >= 60) worst_after_two = std::max(worst_after_two, e);
  }
  // Measured 2.9 px after 1 s and falling: the walk moves 92 px in 0.5 s.
  EXPECT_LT(error_at_half_second, 10.0);
  EXPECT_LT(worst_after_one_second, 4.0);
  EXPECT_LT(worst_after_two, 2.0);
  EXPECT_NEAR(f.velocity().x(), v.x(), 2.0);
  // A plain type-2 loop started at rest lags such a ramp by tens of px for
  // seconds (its settling time is several 1 / (2 pi 0.2 Hz) = 0.8 s).
  TrackingLowpass loop(0.2);
  double loop_error = 0.0;
  for (int i = 0; i <= 30; ++i) {
    const Eigen::Vector2d x = Eigen::Vector2d(100, 200) + v * (i * kDt);
    loop_error = (loop.Update(x, i ? kDt : 0.0) - x).norm();
  }
  EXPECT_GT(loop_error, 50.0);
}

// Drift well below the corner passes; a walking bob or nod (2 Hz) is
// attenuated about as the loop's zero and the low-pass predict: the loop
// passes ~2 x 0.2 / 2 = 0.2 of it, the 1 Hz first-order stage half of that
// or less, the lead adding a little back.
TEST(SlowMotionFilterTest, PassesDriftAndAttenuatesFastMotion) {
  SlowMotionFilter slow(0.2), fast(0.2);
  EXPECT_NEAR(OutputAmplitude(&slow, 0.05, 40.0), 40.0, 3.0);
  const double passed = OutputAmplitude(&fast, 2.0, 10.0) / 10.0;
  std::cout << "2 Hz passes " << passed << " of its amplitude\n";
  EXPECT_LT(passed, 0.2);
}

TEST(SlowMotionFilterTest, ANonPositiveStepRestartsAtTheSample) {
  SlowMotionFilter f(0.2);
  for (int i = 0; i < 30; ++i) f.Update(Eigen::Vector2d(i * 5.0, 0.0), i ? kDt : 0.0);
  const Eigen::Vector2d x(-40.0, 7.0);
  EXPECT_EQ(f.Update(x, 0.0), x);
  EXPECT_EQ(f.velocity(), Eigen::Vector2d::Zero());
  f.Reset();
  EXPECT_FALSE(f.started());
  EXPECT_EQ(f.Update(Eigen::Vector2d(1, 2), kDt), Eigen::Vector2d(1, 2));
}

// A type-2 loop's error on a ramp does not grow: the filter's lag is the
// same after 10 s and after 20 s, and below the first-order stage's v tau.
TEST(TrackingLowpassTest, ARampsLagStaysConstant) {
  const double hz = 0.5, v = 60.0;
  TrackingLowpass f(hz);
  double lag10 = 0.0, lag20 = 0.0;
  for (int i = 0; i <= 600; ++i) {
    const double x = v * i * kDt;
    const double lag = x - f.Update(Eigen::Vector2d(x, 0.0), i ? kDt : 0.0).x();
    if (i == 300) lag10 = lag;
    if (i == 600) lag20 = lag;
  }
  EXPECT_NEAR(lag10, lag20, 1e-3);
  EXPECT_GE(lag20, 0.0);
  EXPECT_LT(lag20, v / (2 * M_PI * 5 * hz));
}

}  // namespace
}  // namespace steadiface

#include "steadiface_core/stabilizer/pose_invariant_centre.h"

#include <cmath>
#include <functional>
#include <iostream>
#include <vector>

#include <gtest/gtest.h>

namespace steadiface {
namespace {

// The options with pivot depth `depth`, yaw time constant `tau` and the
// one-euro filter's speed gain `gain` (0: a plain low-pass).
DynamicWeightOptions Options(double depth, double tau, double gain = 0.0) {
  DynamicWeightOptions o;
  o.pose_pivot_depth = depth;
  o.pose_yaw_time_constant_s = tau;
  o.pose_yaw_speed_gain = gain;
  return o;
}

FaceObservation Turned(double yaw, double scale) {
  FaceObservation f;
  f.valid = true;
  f.has_pose = true;
  f.yaw = yaw;
  f.scale = scale;
  f.landmarks = {Eigen::Vector2d(0.1, 0.2), Eigen::Vector2d(0.3, -0.1)};
  f.centre = Eigen::Vector2d(0.2, 0.05);
  return f;
}

TEST(PoseInvariantCentreTest, MovesTheLandmarksBackByThePivotDepthTimesSinYaw) {
  // A face turned by 0.5 rad whose scale is 0.05: the centre swings by
  // -d sin(yaw) sideways; it is moved back by +1.5 * 0.05 * sin(0.5).
  PoseInvariantCentre c(Options(1.5, 0.1));
  const FaceObservation out = c.Apply(Turned(0.5, 0.05), 0.0);
  const double shift = 1.5 * 0.05 * std::sin(0.5);
  EXPECT_NEAR(out.centre.x(), 0.2 + shift, 1e-12);
  EXPECT_NEAR(out.centre.y(), 0.05, 1e-12);
  EXPECT_NEAR(out.landmarks[0].x(), 0.1 + shift, 1e-12);
  EXPECT_NEAR(out.landmarks[1].y(), -0.1, 1e-12);
  EXPECT_NEAR(c.last_shift(), shift, 1e-12);
}

TEST(PoseInvariantCentreTest, TheYawIsLowPassedAndForgottenWithTheFace) {
  PoseInvariantCentre c(Options(1.0, 0.1));
  c.Apply(Turned(0.0, 1.0), 0.0);
  // One frame (1/30 s) after a step to 0.3 rad: exp(-1/3) of the old yaw.
  c.Apply(Turned(0.3, 1.0), 1.0 / 30.0);
  const double a = std::exp(-1.0 / 3.0);
  EXPECT_NEAR(c.last_shift(), std::sin((1.0 - a) * 0.3), 1e-12);
  // After a reset (the face was lost) the yaw starts again from the face's.
  c.Reset();
  c.Apply(Turned(0.3, 1.0), 1.0 / 30.0);
  EXPECT_NEAR(c.last_shift(), std::sin(0.3), 1e-12);
}

// The yaw a filter with speed gain `gain` reads after `n` frames at 30 fps
// of the readings yaw(k).
double FilteredYaw(double gain, int n, const std::function<double(int)>& yaw) {
  PoseInvariantCentre c(Options(1.0, 0.1, gain));
  for (int k = 0; k < n; ++k) c.Apply(Turned(yaw(k), 1.0), k == 0 ? 0.0 : 1.0 / 30.0);
  return std::asin(c.last_shift());
}

// A head shaken at 2.5 rad/s (140 deg/s): the plain low-pass lags by
// (1 - g) / g frames of the turn, g = 1 - exp(-1/3) its gain per frame
// (0.21 rad: 1.5 face scales of pivot put the centre 0.3 face scales off);
// the one-euro filter opens and lags by a fraction of that. A still head's
// PnP noise (+-0.03 rad from frame to frame, 1.8 rad/s of change, which
// the speed's own 1 Hz low-pass averages to about 0.2 rad/s, below the
// floor) is smoothed exactly as by the plain low-pass.
TEST(PoseInvariantCentreTest, AFastTurnIsNotFollowedLateAndNoiseStaysSmoothed) {
  const auto ramp = [](int k) { return 2.5 * k / 30.0; };
  const double plain_lag = ramp(14) - FilteredYaw(0.0, 15, ramp);
  const double open_lag = ramp(14) - FilteredYaw(5.0, 15, ramp);
  const double g = 1.0 - std::exp(-1.0 / 3.0);
  EXPECT_NEAR(plain_lag, 2.5 / 30.0 * (1.0 - g) / g, 0.01);
  std::cout << "lag after 0.5 s of a 2.5 rad/s turn: plain low-pass " << plain_lag
            << " rad, one-euro " << open_lag << " rad\n";
  EXPECT_LT(open_lag, 0.3 * plain_lag);
  const auto noise = [](int k) { return k % 2 == 0 ? 0.03 : -0.03; };
  const double plain_noise = std::abs(FilteredYaw(0.0, 31, noise));
  const double open_noise = std::abs(FilteredYaw(5.0, 31, noise));
  EXPECT_LT(plain_noise, 0.012);
  EXPECT_NEAR(open_noise, plain_noise, 1e-9);
}

TEST(PoseInvariantCentreTest, WithoutAPoseOrSwitchedOffTheFaceIsUnchanged) {
  FaceObservation no_pose = Turned(0.5, 0.05);
  no_pose.has_pose = false;
  PoseInvariantCentre on(Options(1.5, 0.1)), off(Options(0.0, 0.1));
  EXPECT_EQ(on.Apply(no_pose, 0.03).centre, no_pose.centre);
  EXPECT_EQ(off.Apply(Turned(0.5, 0.05), 0.03).centre,
            Turned(0.5, 0.05).centre);
  FaceObservation nan_yaw = Turned(NAN, 0.05);
  EXPECT_EQ(on.Apply(nan_yaw, 0.03).centre, nan_yaw.centre);
}

// A face nodding by `nod(k)` about a pivot 1.5 face scales behind its
// landmarks, seen by PnP with a pitch offset of 0.1 rad, turned by `yaw`:
// the output centre's height at 30 fps over `n` frames.
std::vector<double> NoddingHeights(int n, double yaw, const std::function<double(int)>& nod,
                                   PoseInvariantCentre* c) {
  std::vector<double> y;
  for (int k = 0; k < n; ++k) {
    FaceObservation f = Turned(yaw, 0.05);
    f.pitch = 0.1 + nod(k);
    f.centre.y() += 1.5 * 0.05 * std::sin(nod(k));  // the landmarks move down
    y.push_back(c->Apply(f, 1.0 / 30.0).centre.y());
  }
  return y;
}

double RmsAboutMean(const std::vector<double>& v, int from) {
  double m = 0.0, s2 = 0.0;
  for (size_t k = from; k < v.size(); ++k) m += v[k];
  m /= v.size() - from;
  for (size_t k = from; k < v.size(); ++k) s2 += (v[k] - m) * (v[k] - m);
  return std::sqrt(s2 / (v.size() - from));
}

TEST(PoseInvariantCentreTest, ANodIsMovedBackByItsShareAndAHeldTiltIsNot) {
  DynamicWeightOptions o = Options(1.5, 0.0);  // no low-pass: exact shares
  o.pose_nod_gain = 0.4;
  o.pose_nod_time_constant_s = 1.0;
  // A walking head's nod: 0.02 rad at 1.8 Hz. Without the share the centre
  // moves by 1.5 * 0.05 * sin(nod); with it, by about 0.6 of that (the slow
  // mean ripples a little at 1.8 Hz).
  const auto nod = [](int k) { return 0.02 * std::sin(2.0 * M_PI * 1.8 * k / 30.0); };
  PoseInvariantCentre on(o);
  o.pose_nod_gain = 0.0;
  PoseInvariantCentre off(o);
  const double moved = RmsAboutMean(NoddingHeights(150, 0.0, nod, &off), 60);
  const double kept = RmsAboutMean(NoddingHeights(150, 0.0, nod, &on), 60);
  std::cout << "nod: centre height RMS " << moved << " without, " << kept << " with the share\n";
  EXPECT_NEAR(moved, 1.5 * 0.05 * 0.02 / std::sqrt(2.0), 2e-5);
  EXPECT_GT(kept, 0.55 * moved);
  EXPECT_LT(kept, 0.66 * moved);
  // A head held tilted 0.2 rad further is not a nod: after 5 s (five time
  // constants) less than 1 % of its shift is left.
  PoseInvariantCentre tilt(Options(1.5, 0.0));
  NoddingHeights(150, 0.0, [](int k) { return k < 1 ? 0.0 : 0.2; }, &tilt);
  EXPECT_LT(std::abs(tilt.last_nod_shift()), 0.01 * 0.4 * 1.5 * 0.05 * std::sin(0.2));
  EXPECT_GT(std::abs(tilt.last_nod_shift()), 0.0);
}

TEST(PoseInvariantCentreTest, ATurnedFacesPitchIsNotTakenForANod) {
  // Past twice pose_nod_max_yaw (0.15 rad) the nod's shift is gone; at it,
  // all of it is kept.
  const auto nod = [](int k) { return 0.02 * std::sin(2.0 * M_PI * 1.8 * k / 30.0); };
  PoseInvariantCentre turned(Options(1.5, 0.0)), facing(Options(1.5, 0.0));
  NoddingHeights(40, 0.35, nod, &turned);
  NoddingHeights(40, 0.15, nod, &facing);
  EXPECT_EQ(turned.last_nod_shift(), 0.0);
  EXPECT_NE(facing.last_nod_shift(), 0.0);
}

}  // namespace
}  // namespace steadiface

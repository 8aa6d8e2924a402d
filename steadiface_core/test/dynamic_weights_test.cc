// DynamicWeights (paper 4.4) directly, in closed form: each factor's target
// from its input, the first-order fade with the frame's dt, the first
// frame's jump, and the switch that turns it all off.
#include "steadiface_core/stabilizer/dynamic_weights.h"

#include <cmath>

#include <gtest/gtest.h>

namespace steadiface {
namespace {

FaceObservation Face(double yaw = 0.0) {
  FaceObservation f;
  f.valid = true;
  f.has_pose = true;
  f.yaw = yaw;
  f.scale = 0.1;
  return f;
}

const Eigen::Vector2d kCentre(0.5, 0.5);

TEST(SmoothStepTest, IsZeroBelowOneAboveAndC1Between) {
  EXPECT_EQ(SmoothStep(0.0, 1.0, 2.0), 0.0);
  EXPECT_EQ(SmoothStep(2.5, 1.0, 2.0), 1.0);
  EXPECT_DOUBLE_EQ(SmoothStep(1.5, 1.0, 2.0), 0.5);
  EXPECT_DOUBLE_EQ(SmoothStep(1.25, 1.0, 2.0), 0.25 * 0.25 * (3.0 - 0.5));
  // Flat at both ends: the difference quotient vanishes there.
  EXPECT_LT((SmoothStep(1.0 + 1e-4, 1.0, 2.0) - SmoothStep(1.0, 1.0, 2.0)) / 1e-4, 1e-3);
  EXPECT_LT((SmoothStep(2.0, 1.0, 2.0) - SmoothStep(2.0 - 1e-4, 1.0, 2.0)) / 1e-4, 1e-3);
  EXPECT_EQ(SmoothStep(3.0, 2.0, 2.0), 1.0);  // a degenerate range is a step
}

// The gyro factor: gyro_still_fit_scale for a still camera, 1 for an active
// one, the smooth step between; an unknown speed counts as active.
TEST(DynamicWeightsTest, TheGyroTargetFollowsTheCamerasSpeed) {
  DynamicWeightOptions o;
  o.gyro_still_fit_scale = 0.2;
  const FaceObservation face = Face();
  for (const double speed : {0.0, o.gyro_still_rad_s, 0.5 * (o.gyro_still_rad_s + o.gyro_active_rad_s),
                             o.gyro_active_rad_s, 1.0, -1.0}) {
    DynamicWeights w(o);
    const WeightFactors f = w.Update(0.0, speed, &face, kCentre, 0.1);
    const double expected =
        speed < 0.0 ? 1.0
                    : 0.2 + 0.8 * SmoothStep(speed, o.gyro_still_rad_s, o.gyro_active_rad_s);
    EXPECT_DOUBLE_EQ(f.gyro_target, expected) << speed;
    EXPECT_DOUBLE_EQ(f.fit, expected) << speed;  // the first frame jumps to it
  }
}

// A turned head lowers w_f to pose_min_fit_scale and raises the smoothness
// weights by (1 + boost).
TEST(DynamicWeightsTest, ATurnedHeadLowersTheFitAndRaisesSmoothness) {
  const DynamicWeightOptions o;
  DynamicWeights w(o);
  const FaceObservation turned = Face(o.pose_high_rad + 0.1);
  const WeightFactors f = w.Update(0.0, 1.0, &turned, kCentre, 0.1);
  EXPECT_DOUBLE_EQ(f.pose_target, o.pose_min_fit_scale);
  EXPECT_DOUBLE_EQ(f.fit, o.pose_min_fit_scale);
  EXPECT_DOUBLE_EQ(f.smoothness, 1.0 + o.pose_smoothness_boost);
  DynamicWeights w2(o);
  const FaceObservation frontal = Face(0.5 * o.pose_low_rad);
  const WeightFactors g = w2.Update(0.0, 1.0, &frontal, kCentre, 0.1);
  EXPECT_DOUBLE_EQ(g.fit, 1.0);
  EXPECT_DOUBLE_EQ(g.smoothness, 1.0);
}

// After the first frame each factor approaches its target by
// 1 - exp(-dt / fade_time) of the gap per frame: a face that disappears
// fades w_f out exponentially, and comes back the same way.
TEST(DynamicWeightsTest, FactorsFadeWithTheFramesDt) {
  const DynamicWeightOptions o;
  DynamicWeights w(o);
  const FaceObservation face = Face();
  ASSERT_DOUBLE_EQ(w.Update(0.0, 1.0, &face, kCentre, 0.1).fit, 1.0);
  const double dt = 1.0 / 30.0, a = 1.0 - std::exp(-dt / o.fade_time_s);
  double expected = 1.0;
  for (int i = 0; i < 10; ++i) {
    const WeightFactors f = w.Update(dt, 1.0, nullptr, kCentre, 0.1);
    expected += a * (0.0 - expected);
    EXPECT_NEAR(f.fit, expected, 1e-12) << i;
    EXPECT_EQ(f.presence_target, 0.0);
  }
  const double low = expected;
  const WeightFactors back = w.Update(dt, 1.0, &face, kCentre, 0.1);
  EXPECT_NEAR(back.fit, low + a * (1.0 - low), 1e-12);
  // A dt of 0 (a repeated stamp) has no time to fade over: the factors are
  // their targets.
  EXPECT_DOUBLE_EQ(w.Update(0.0, 1.0, &face, kCentre, 0.1).fit, 1.0);
}

// Landmarks whose gyro-compensated centre jitters (large second
// differences) lower w_f to variation_min_fit_scale; a steady face keeps
// it at 1. The window needs 3 frames before it judges.
TEST(DynamicWeightsTest, JitteryLandmarksLowerTheFit) {
  DynamicWeightOptions o;
  o.fade_time_s = 0.0;  // no fade: the factors are their targets
  const FaceObservation face = Face();
  DynamicWeights steady(o), jittery(o);
  WeightFactors fs, fj;
  for (int i = 0; i < o.variation_window; ++i) {
    const Eigen::Vector2d moving = kCentre + Eigen::Vector2d(0.001 * i, 0.0);  // constant speed
    const Eigen::Vector2d shaking = kCentre + Eigen::Vector2d(i % 2 ? 0.02 : -0.02, 0.0);
    fs = steady.Update(1.0 / 30, 1.0, &face, moving, 0.1);
    fj = jittery.Update(1.0 / 30, 1.0, &face, shaking, 0.1);
    if (i < 2) EXPECT_EQ(fj.variation_target, 1.0) << i;
  }
  EXPECT_NEAR(fs.centre_variation, 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(fs.fit, 1.0);
  EXPECT_NEAR(fj.centre_variation, 0.08, 1e-12);  // |+-0.02 second difference| = 0.08
  EXPECT_DOUBLE_EQ(fj.fit, o.variation_min_fit_scale);
}

// enabled false: the base weights, with only the face's presence.
TEST(DynamicWeightsTest, DisabledKeepsOnlyThePresence) {
  DynamicWeightOptions o;
  o.enabled = false;
  DynamicWeights w(o);
  const FaceObservation turned = Face(1.2);
  const WeightFactors f = w.Update(0.0, 0.0, &turned, kCentre, 0.1);  // still, turned
  EXPECT_DOUBLE_EQ(f.fit, 1.0);
  EXPECT_DOUBLE_EQ(f.smoothness, 1.0);
  w.Reset();
  EXPECT_DOUBLE_EQ(w.Update(0.0, 0.0, nullptr, kCentre, 0.1).fit, 0.0);
}

}  // namespace
}  // namespace steadiface

// The presets that judge a stabilizer where the head moves against a steady
// scene: `drift` (handheld tremor, the head drifting and turning) and
// `walk_across` (the subject walks across the view). Their motion is
// checked against the options' closed forms and the renderer's truth.
#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>

#include <gtest/gtest.h>

#include "sim_util.h"
#include "steadiface_core/common/so3.h"
#include "steadiface_core/sim/motion.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace {

using testing_util::MakeSimulator;

sim::HeadMotionOptions StillHead() {
  sim::HeadMotionOptions h;
  h.bob_amplitude_m = h.sway_amplitude_m = h.jitter_rms_m = 0.0;
  h.yaw_amplitude_rad = h.pitch_amplitude_rad = h.lean_amplitude_m = 0.0;
  return h;
}

TEST(SimPresetsTest, HeadDriftAndWalkFollowTheirClosedForms) {
  sim::HeadMotionOptions h = StillHead();
  h.drift_amplitude_m = 0.05;
  h.drift_hz = 0.2;
  const sim::HeadMotion drift(h);
  for (double t : {0.0, 0.4, 1.3, 2.9}) {
    const Eigen::Vector3d p = drift.Position(t);
    EXPECT_NEAR(p.x(), 0.05 * std::sin(2 * M_PI * 0.2 * t), 1e-12);
    EXPECT_NEAR(p.y(), 0.025 * std::sin(0.7 * 2 * M_PI * 0.2 * t + 0.5), 1e-12);
    EXPECT_NEAR(p.z(), h.distance_m, 1e-12);
  }
  h = StillHead();
  h.walk_start_x_m = -0.35;
  h.walk_speed_m_s = 0.25;
  const sim::HeadMotion walk(h);
  for (double t : {0.0, 1.0, 2.8}) {
    EXPECT_NEAR(walk.Position(t).x(), -0.35 + 0.25 * t, 1e-12);
  }
}

TEST(SimPresetsTest, DriftIsASmallTremorWhileTheHeadDriftsAndTurns) {
  auto s = MakeSimulator("drift");
  const int n = s->num_frames();
  ASSERT_EQ(n, 90);
  // The camera's tremor: the true rotation's deviation from its mean,
  // about 0.15 deg RMS per axis (a band-limited sum over 3 s).
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> rv;
  const Eigen::Quaterniond q0 = s->Truth(0).R_r[s->Truth(0).R_r.size() / 2];
  for (int i = 0; i < n; ++i) {
    const sim::SimTruth t = s->Truth(i);
    rv.push_back(LogSO3(t.R_r[t.R_r.size() / 2] * q0.conjugate()));
    mean += rv.back() / n;
  }
  Eigen::Vector3d ms = Eigen::Vector3d::Zero();
  for (const auto& v : rv) ms += (v - mean).cwiseAbs2() / n;
  const double deg = 180.0 / M_PI;
  for (int a = 0; a < 3; ++a) {
    EXPECT_GT(std::sqrt(ms[a]) * deg, 0.05) << a;
    EXPECT_LT(std::sqrt(ms[a]) * deg, 0.3) << a;
  }
  // With the camera frozen, the head still crosses tens of pixels: the
  // drift (5 cm at 0.6 m) and the turning, against a still scene.
  auto frozen = MakeSimulator("drift", [](sim::SimulatorOptions* o) {
    o->camera.shake_rms_rad = 0.0;
    o->camera.translation_rms_m = 0.0;
  });
  double lo = 1e9, hi = -1e9;
  for (int i = 0; i < n; ++i) {
    const sim::SimTruth t = frozen->Truth(i);
    ASSERT_TRUE(t.head_in_view) << i;
    lo = std::min(lo, t.head_px.x());
    hi = std::max(hi, t.head_px.x());
  }
  EXPECT_GT(hi - lo, 30.0);
}

TEST(SimPresetsTest, WalkAcrossCrossesTheViewWithTheFaceInView) {
  auto s = MakeSimulator("walk_across");
  const int n = s->num_frames();
  const double w = s->intrinsics().width;
  const sim::SimTruth first = s->Truth(0), last = s->Truth(n - 1);
  EXPECT_LT(first.head_px.x(), 0.3 * w);
  EXPECT_GT(last.head_px.x(), 0.7 * w);
  for (int i = 0; i < n; ++i) {
    const sim::SimTruth t = s->Truth(i);
    EXPECT_TRUE(t.head_in_view) << i;
    EXPECT_GT(t.face_scale_px, 70.0) << i;  // dlib's detector finds it
  }
}

}  // namespace
}  // namespace steadiface

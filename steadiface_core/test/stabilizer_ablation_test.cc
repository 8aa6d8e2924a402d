// The paper's ablations (Figs. 4-6) as measurements: each term of Eq. 5
// switched off on ground-truth landmark sequences.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "steadiface_core/common/so3.h"
#include "steadiface_core/stabilizer/stabilizer.h"
#include "stabilizer_test_util.h"
#include "test_util.h"

namespace steadiface {
namespace {

using testing_util::Model640x360;
using testing_util::Print;
using testing_util::RunResult;
using testing_util::RunSequence;
using testing_util::Walk;

// Paper Figs. 4-6 as measurements: each term's ablation.
double MeanVirtualRealAngle(const RunResult& r) {
  double s = 0.0;
  for (const auto& f : r.frames_out) s += AngleBetween(f.R_v, f.R_r);
  return s / r.frames_out.size();
}

double Roughness(const RunResult& r, bool rotation) {
  double s2 = 0.0;
  int n = 0;
  for (size_t i = 2; i < r.frames_out.size(); ++i) {
    const auto& a = r.frames_out[i - 2];
    const auto& b = r.frames_out[i - 1];
    const auto& c = r.frames_out[i];
    const double d = rotation
                         ? AngleBetween(c.R_v * b.R_v.conjugate(), b.R_v * a.R_v.conjugate())
                         : (c.t - 2.0 * b.t + a.t).norm();
    s2 += d * d;
    ++n;
  }
  return std::sqrt(s2 / n);
}

TEST(StabilizerAblationTest, FollowingAndDistortionTermsHoldThePoseDuringAPan) {
  // Paper Fig. 5: virtual camera deviation with/without E_o and E_d. Each
  // term alone is compared with neither; E_p is off so that drift shows up
  // as post-solve protrusion searches (the paper's fallback).
  const CameraModel m = Model640x360();
  sim::LandmarkSequenceOptions o = Walk();
  o.camera.pan_rate = 0.25;  // rad/s, ramped in over 2 s
  o.duration_s = 6.0;
  const sim::LandmarkSequence seq(m, o);
  StabilizerOptions so;
  so.gyro_only = true;  // isolate the rotation terms
  so.weights.distortion = 0.0;
  so.weights.protrusion = 0.0;  // leave only the post-solve binary search
  // E_d's default threshold (0.15 rad) is about what the 15 % crop admits,
  // so on this pan the crop binds first; a threshold inside the crop's
  // reach shows what the term does.
  so.terms.distortion_threshold_rad = 0.05;
  const RunResult follow_only = RunSequence(m, seq, so);
  so.weights.follow = 0.0;
  const RunResult neither = RunSequence(m, seq, so);
  so.weights.distortion = StabilizerOptions().weights.distortion;
  const RunResult distortion_only = RunSequence(m, seq, so);
  auto searches = [](const RunResult& r) {
    int n = 0;
    for (const auto& f : r.frames_out) n += f.flags.protrusion_search;
    return n;
  };
  std::cout << "[ ablation E_o/E_d, pan ] mean virtual-real angle: E_o only "
            << MeanVirtualRealAngle(follow_only) << ", E_d only "
            << MeanVirtualRealAngle(distortion_only) << ", neither "
            << MeanVirtualRealAngle(neither) << " rad; protrusion searches "
            << searches(follow_only) << " / " << searches(distortion_only) << " / "
            << searches(neither) << "\n";
  // At the default weights E_o is the weak one (it mostly trims the drift
  // and the fallbacks); E_d holds the pose near the real one.
  EXPECT_LT(MeanVirtualRealAngle(follow_only), MeanVirtualRealAngle(neither));
  EXPECT_LT(MeanVirtualRealAngle(distortion_only), 0.6 * MeanVirtualRealAngle(neither));
  EXPECT_GT(searches(neither), searches(follow_only));
  EXPECT_GT(searches(neither), searches(distortion_only));
  EXPECT_EQ(follow_only.undefined + distortion_only.undefined + neither.undefined, 0);
}

TEST(StabilizerAblationTest, WithoutSmoothnessThePoseIsRougher) {
  const CameraModel m = Model640x360();
  const sim::LandmarkSequence seq(m, Walk());
  StabilizerOptions so;
  const RunResult with = RunSequence(m, seq, so);
  so.weights.rotation_c0 = so.weights.rotation_c1 = 0.0;
  so.weights.translation_c0 = 1e-6;
  so.weights.translation_c1 = 0.0;
  const RunResult without = RunSequence(m, seq, so);
  const double rot_w = Roughness(with, true), rot_wo = Roughness(without, true);
  const double t_w = Roughness(with, false), t_wo = Roughness(without, false);
  std::cout << "[ ablation E_r/E_t ] rotation roughness " << rot_w << " vs " << rot_wo
            << " rad; offset roughness " << t_w << " vs " << t_wo << "\n";
  EXPECT_GT(rot_wo, 1.3 * rot_w);
  EXPECT_GT(t_wo, 1.3 * t_w);
}

TEST(StabilizerAblationTest, PaperLiteralHeadSmoothingAlsoBeatsGyroOnly) {
  const CameraModel m = Model640x360();
  const sim::LandmarkSequence seq(m, Walk());
  StabilizerOptions so;
  so.smooth_head_in_virtual_view = false;
  const RunResult literal = RunSequence(m, seq, so);
  so.smooth_head_in_virtual_view = true;
  const RunResult ours = RunSequence(m, seq, so);
  so.gyro_only = true;
  const RunResult gyro = RunSequence(m, seq, so);
  std::cout << "[ head smoothing domain ] head jitter: paper-literal " << literal.output.head_px
            << " px, virtual-view " << ours.output.head_px << " px, gyro-only "
            << gyro.output.head_px << " px\n";
  EXPECT_LT(literal.output.head_px, 0.7 * gyro.output.head_px);
  EXPECT_LT(ours.output.head_px, 0.6 * literal.output.head_px);
}


}  // namespace
}  // namespace steadiface

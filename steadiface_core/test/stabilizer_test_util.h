#pragma once
// The stabilizer on ground-truth landmark sequences, for its tests
// (stabilizer_test.cc, stabilizer_ablation_test.cc): a runner that scores
// head and background jitter, and the sequences it runs.

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "steadiface_core/sim/landmark_sequence.h"
#include "steadiface_core/stabilizer/stabilizer.h"

namespace steadiface {
namespace testing_util {

struct Jitter {
  double head_px = 0.0, background_px = 0.0;
};

// RMS of x - (centred moving average over `win` frames): a ~fps/win Hz
// high-pass, on the frames where the whole window exists.
inline double HighPassRms(const std::vector<Eigen::Vector2d>& x, int win) {
  double s2 = 0.0;
  int n = 0;
  for (int i = win / 2; i + win / 2 < static_cast<int>(x.size()); ++i) {
    Eigen::Vector2d avg = Eigen::Vector2d::Zero();
    for (int j = i - win / 2; j <= i + win / 2; ++j) avg += x[j];
    avg /= (2 * (win / 2) + 1);
    s2 += (x[i] - avg).squaredNorm();
    ++n;
  }
  return std::sqrt(s2 / std::max(1, n));
}

struct RunResult {
  Jitter input, output;
  int undefined = 0, fallbacks = 0, frames = 0;
  std::vector<StabilizerFrame> frames_out;
};

// `reach_limit` > 0: Stabilizer::SetReachLimit before every frame.
inline RunResult RunSequence(const CameraModel& m, const sim::LandmarkSequence& seq,
              StabilizerOptions so, double reach_limit = 0.0) {
  std::unique_ptr<Stabilizer> stab;
  OutputOptions oo;
  oo.crop_ratio = 0.1;
  EXPECT_TRUE(Stabilizer::Create(m, oo, so, &stab).ok());
  OrientationTimeline tl{OrientationTimelineOptions()};
  size_t g = 0;
  RunResult rr;
  std::vector<Eigen::Vector2d> head_in, head_out, bg_in, bg_out;
  const Eigen::Vector3d bg_dir(0.2, -0.1, 1.0);
  const double W = m.intrinsics().width;
  for (size_t i = 0; i < seq.frames().size(); ++i) {
    const auto& fr = seq.frames()[i];
    // Feed gyro up to the last row (as the node does).
    while (g < seq.gyro().size() &&
           seq.gyro()[g].stamp <= seq.timing().LastRowTime(fr.stamp)) {
      tl.AddSample(seq.gyro()[g++]);
    }
    if (g < seq.gyro().size()) tl.AddSample(seq.gyro()[g++]);
    StabilizerFrame out;
    if (reach_limit > 0.0) stab->SetReachLimit(reach_limit);
    const Status s = stab->Process(fr.stamp, tl, seq.timing(), &fr.observed, &out);
    EXPECT_TRUE(s.ok()) << s.message();
    // Output head: the true landmarks through the solved pose, each with its
    // row's real rotation.
    Eigen::Vector2d h = Eigen::Vector2d::Zero();
    for (size_t k = 0; k < fr.true_landmarks.size(); ++k) {
      Eigen::Vector2d p;
      EXPECT_TRUE(m.Project(fr.true_landmarks[k], out.R_v, out.t,
                            out.rows.At(fr.true_rows[k]), &p));
      h += p;
    }
    h /= fr.true_landmarks.size();
    head_in.push_back(fr.true_centre * W);
    head_out.push_back(h * W);
    Eigen::Vector2d b, bo;
    double row;
    EXPECT_TRUE(seq.BackgroundPoint(static_cast<int>(i), bg_dir, &b, &row));
    EXPECT_TRUE(m.Project(b, out.R_v, out.t, out.rows.At(row), &bo));
    bg_in.push_back(b * W);
    bg_out.push_back(bo * W);
    EXPECT_TRUE(out.R_v.coeffs().allFinite());
    EXPECT_TRUE(out.t.allFinite());
    rr.frames_out.push_back(out);
  }
  const int win = 61;  // ~0.5 Hz at 30 fps
  rr.input = {HighPassRms(head_in, win), HighPassRms(bg_in, win)};
  rr.output = {HighPassRms(head_out, win), HighPassRms(bg_out, win)};
  rr.undefined = static_cast<int>(stab->stats().undefined_frames);
  rr.fallbacks = static_cast<int>(stab->stats().previous_warp_fallbacks);
  rr.frames = static_cast<int>(stab->stats().frames);
  return rr;
}

inline sim::LandmarkSequenceOptions Walk() {
  sim::LandmarkSequenceOptions o;
  o.duration_s = 6.0;
  o.camera.shake_rms_rad = 0.012;
  o.camera.translation_rms_m = 0.002;
  o.shutter.readout_time_s = 0.02;
  o.landmark_noise_px = 0.7;
  o.gyro_noise = 0.003;
  return o;
}

// Walking with violent shake (0.03 rad RMS), 3 s: more than RunSequence's
// 10 % crop can hold.
inline sim::LandmarkSequenceOptions ViolentShake() {
  sim::LandmarkSequenceOptions o = Walk();
  o.camera.shake_rms_rad = 0.03;
  o.duration_s = 3.0;
  return o;
}

inline void Print(const char* name, const RunResult& r) {
  std::cout << "[ " << name << " ] head jitter in " << r.input.head_px
            << " px -> " << r.output.head_px << " px; background "
            << r.input.background_px << " -> " << r.output.background_px
            << " px; undefined frames " << r.undefined << "/" << r.frames
            << "\n";
}

}  // namespace testing_util
}  // namespace steadiface

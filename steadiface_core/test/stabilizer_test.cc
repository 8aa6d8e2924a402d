// The whole stabilizer on ground-truth sequences (simulated landmarks and
// gyro): jitter against the input and gyro-only, face loss, protrusion,
// determinism, the background layer. Its terms one by one are in
// stabilizer_terms_test.cc, their ablations in stabilizer_ablation_test.cc.
#include "steadiface_core/stabilizer/stabilizer.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <iostream>
#include <memory>

#include <gtest/gtest.h>

#include "steadiface_core/common/so3.h"
#include "steadiface_core/sim/landmark_sequence.h"
#include "steadiface_core/stabilizer/face_in_camera.h"
#include "steadiface_core/stabilizer/pose_invariant_centre.h"
#include "stabilizer_test_util.h"
#include "test_util.h"

namespace steadiface {
namespace {

using testing_util::At;
using testing_util::Model640x360;
using testing_util::Print;
using testing_util::RunResult;
using testing_util::RunSequence;
using testing_util::ViolentShake;
using testing_util::Walk;

// ---------- Stabilizer on ground-truth sequences ----------


TEST(StabilizerTest, BeatsGyroOnlyOnHeadJitterWalking) {
  const CameraModel m = Model640x360();
  const sim::LandmarkSequence seq(m, Walk());
  StabilizerOptions so;
  const RunResult full = RunSequence(m, seq, so);
  so.gyro_only = true;
  const RunResult gyro = RunSequence(m, seq, so);
  Print("walk steadiface", full);
  Print("walk gyro-only", gyro);
  EXPECT_LE(full.output.head_px, 0.5 * gyro.output.head_px);
  EXPECT_LE(full.output.head_px, 0.3 * full.input.head_px);
  // Gyro-only removes nearly all background jitter. Steadiface keeps it below
  // the input's: holding the head still must move the background by the
  // head-vs-camera translation (no global warp can avoid that), so the floor
  // is gyro-only's residual head jitter (~6 px here), not zero. The head
  // also nods about its skull's centre, which moves its landmarks; the
  // pose-invariant centre takes back the turn (yaw), not the nod.
  EXPECT_LE(gyro.output.background_px, 0.1 * gyro.input.background_px);
  EXPECT_LE(full.output.background_px, 0.8 * full.input.background_px);
  EXPECT_LE(full.output.background_px, 1.1 * gyro.output.head_px);
  EXPECT_EQ(full.undefined, 0);
  EXPECT_EQ(gyro.undefined, 0);
}

// The background layer (issue 15's second virtual camera) is exactly the
// gyro-only pose, solved alongside the face-following one with its own
// state; turning it on leaves the face-following layer untouched. The face
// drops out for a while, so the layers must stay apart through a loss.
TEST(StabilizerTest, BackgroundLayerIsExactlyTheGyroOnlyPoseAndLeavesTheSubjectAlone) {
  const CameraModel m = Model640x360();
  sim::LandmarkSequenceOptions o = Walk();
  o.face_lost_from = 60;
  o.face_lost_to = 90;
  const sim::LandmarkSequence seq(m, o);
  StabilizerOptions so;
  const RunResult one = RunSequence(m, seq, so);
  so.background_layer = true;
  const RunResult two = RunSequence(m, seq, so);
  StabilizerOptions go;
  go.gyro_only = true;
  const RunResult gyro = RunSequence(m, seq, go);
  ASSERT_EQ(one.frames_out.size(), two.frames_out.size());
  ASSERT_EQ(gyro.frames_out.size(), two.frames_out.size());
  double max_layer_gap = 0.0;
  for (size_t i = 0; i < two.frames_out.size(); ++i) {
    const StabilizerFrame& a = one.frames_out[i];
    const StabilizerFrame& b = two.frames_out[i];
    const StabilizerFrame& g = gyro.frames_out[i];
    EXPECT_FALSE(a.background.valid);
    ASSERT_TRUE(b.background.valid);
    // Subject layer: bit for bit as with one layer.
    EXPECT_EQ(a.R_v.coeffs(), b.R_v.coeffs()) << "frame " << i;
    EXPECT_EQ(a.t, b.t) << "frame " << i;
    // Background layer: bit for bit the gyro-only run.
    EXPECT_EQ(b.background.R_v.coeffs(), g.R_v.coeffs()) << "frame " << i;
    EXPECT_EQ(b.background.t, g.t) << "frame " << i;
    max_layer_gap = std::max(
        max_layer_gap, Eigen::AngleAxisd(b.R_v * b.background.R_v.conjugate()).angle());
  }
  // The two layers really differ (the face-following one moves with the
  // head): by tenths of a degree or more.
  EXPECT_GT(max_layer_gap, 0.003);
  std::printf("  background layer: %zu frames equal to gyro-only; layers up to %.2f deg apart\n",
              two.frames_out.size(), max_layer_gap * 180.0 / M_PI);
}

// subject_reach: H stays within the reach of where the background layer
// shows the face (in jaw widths), and the background layer stays bit for
// bit the gyro-only pose; without the reach H leaves it. A reach limit
// from the warp (SetReachLimit: what the band absorbs) tightens it further
// and never loosens it.
TEST(StabilizerTest, SubjectReachHoldsTheTargetNearTheBackgroundLayersFace) {
  const CameraModel m = Model640x360();
  const sim::LandmarkSequence seq(m, Walk());
  auto worst_over_reach = [&](double reach, double limit) {
    StabilizerOptions so;
    so.background_layer = true;
    so.subject_reach = reach;
    const RunResult r = RunSequence(m, seq, so, limit);
    StabilizerOptions go;
    go.gyro_only = true;
    const RunResult gyro = RunSequence(m, seq, go);
    double worst = 0.0;  // max |H - C_bg| / jaw width
    // The face as the stabilizer reads it: at the pose-invariant centre.
    PoseInvariantCentre invariant(so.dynamic);
    for (size_t i = 0; i < r.frames_out.size(); ++i) {
      const StabilizerFrame& f = r.frames_out[i];
      EXPECT_EQ(f.background.R_v.coeffs(), gyro.frames_out[i].R_v.coeffs()) << i;
      const FaceObservation observed = invariant.Apply(
          seq.frames()[i].observed,
          i == 0 ? 0.0 : ToSeconds(seq.frames()[i].stamp - seq.frames()[i - 1].stamp));
      if (!f.has_target) continue;
      FaceObservation seen;
      EXPECT_TRUE(FaceInCamera(m, observed, f.rows, f.R_r, f.background.R_v,
                               f.background.t, &seen));
      const double jaw = (seen.landmarks[0] - seen.landmarks[16]).norm();
      worst = std::max(worst, (f.H - seen.centre).norm() / jaw);
    }
    return worst;
  };
  EXPECT_LE(worst_over_reach(0.05, 0.0), 0.05 + 1e-9);
  EXPECT_GT(worst_over_reach(0.05, 0.0), 0.04);  // so the reach binds on this sequence
  EXPECT_LE(worst_over_reach(0.05, 0.02), 0.02 + 1e-9);
  EXPECT_GT(worst_over_reach(0.05, 0.02), 0.015);
  EXPECT_LE(worst_over_reach(0.05, 0.2), 0.05 + 1e-9);  // a looser limit changes nothing
  EXPECT_GT(worst_over_reach(0.0, 0.0), 0.08);  // without a reach H leaves it
}

TEST(StabilizerTest, StillCameraGivesStillVirtualCamera) {
  const CameraModel m = Model640x360();
  sim::LandmarkSequenceOptions o = Walk();
  o.camera.shake_rms_rad = 0.0;
  o.camera.translation_rms_m = 0.0;
  o.gyro_noise = 0.002;
  const sim::LandmarkSequence seq(m, o);
  const RunResult r = RunSequence(m, seq, StabilizerOptions());
  // The head moves (bob, sway), but the virtual camera barely does.
  double max_angle = 0.0, max_t = 0.0;
  for (const auto& f : r.frames_out) {
    max_angle = std::max(max_angle, AngleBetween(f.R_v, f.R_r));
    max_t = std::max(max_t, f.t.norm());
  }
  std::cout << "[ still ] max virtual-real angle " << max_angle
            << " rad, max |t| " << max_t << "\n";
  EXPECT_LT(max_angle, 0.01);
  EXPECT_LT(max_t * m.intrinsics().width, 8.0);
  EXPECT_LT(r.frames_out.back().factors.fit, 0.2);
}

TEST(StabilizerTest, FaceLossFadesWeightsWithoutJumps) {
  const CameraModel m = Model640x360();
  sim::LandmarkSequenceOptions o = Walk();
  o.face_lost_from = 60;
  o.face_lost_to = 100;
  const sim::LandmarkSequence seq(m, o);
  const RunResult r = RunSequence(m, seq, StabilizerOptions());
  // Jumps show up as outliers of the virtual camera's second difference
  // (its angular acceleration, and the offset's), compared between the
  // frames around the loss and re-acquisition and a steady tracked stretch.
  auto d2_rot = [&](size_t i) {
    const auto& a = r.frames_out[i - 2];
    const auto& b = r.frames_out[i - 1];
    const auto& c = r.frames_out[i];
    return AngleBetween(c.R_v * b.R_v.conjugate(), b.R_v * a.R_v.conjugate());
  };
  auto d2_t = [&](size_t i) {
    return (r.frames_out[i].t - 2.0 * r.frames_out[i - 1].t + r.frames_out[i - 2].t).norm();
  };
  double steady_rot = 0.0, steady_t = 0.0, event_rot = 0.0, event_t = 0.0;
  double max_fit_step = 0.0;
  for (size_t i = 2; i < r.frames_out.size(); ++i) {
    const bool event = i >= 58 && i < 125;
    const bool steady = i >= 20 && i < 58;
    if (event) {
      event_rot = std::max(event_rot, d2_rot(i));
      event_t = std::max(event_t, d2_t(i));
    } else if (steady) {
      steady_rot = std::max(steady_rot, d2_rot(i));
      steady_t = std::max(steady_t, d2_t(i));
    }
    max_fit_step = std::max(
        max_fit_step, std::abs(r.frames_out[i].factors.fit - r.frames_out[i - 1].factors.fit));
  }
  std::cout << "[ face loss ] max w_f factor step " << max_fit_step
            << "; max rotation 2nd difference steady " << steady_rot
            << " rad vs around loss/re-acquisition " << event_rot
            << "; offset 2nd difference steady " << steady_t << " vs " << event_t << "\n";
  EXPECT_LT(max_fit_step, 0.15);  // fades over several frames
  EXPECT_LT(event_rot, 1.5 * steady_rot + 1e-4);
  EXPECT_LT(event_t, 1.5 * steady_t + 1e-4);
  EXPECT_EQ(r.undefined, 0);
  // During the loss the weight is (nearly) 0 and E_f is absent.
  EXPECT_LT(r.frames_out[95].factors.fit, 0.01);
  EXPECT_FALSE(r.frames_out[95].flags.face_used);
}

// E_p's softer tolerance belongs to a face that E_f fits in the same solve.
// After a long loss the held face is let go once w_f is below 1e-3 of its
// nominal, but w_f goes on fading towards 0 while no face is fitted: those
// solves keep the paper's stiff wall exactly.
TEST(StabilizerTest, ProtrusionToleranceOnlyWhereAFaceIsFitted) {
  const CameraModel m = Model640x360();
  sim::LandmarkSequenceOptions o = Walk();
  o.face_lost_from = 60;
  o.face_lost_to = 170;  // 3.7 s, past the held face's 1.7 s
  const sim::LandmarkSequence seq(m, o);
  const StabilizerOptions so;
  const RunResult r = RunSequence(m, seq, so);
  int fitted = 0, fading_unfitted = 0;
  for (const StabilizerFrame& f : r.frames_out) {
    if (!f.solver.ran || f.weights.protrusion <= 0.0) continue;
    const bool face = f.flags.face_used || f.flags.held_face;
    const double expected =
        face ? ProtrusionAlpha(so.terms, f.weights.fit, so.weights.fit) : so.terms.protrusion_alpha;
    EXPECT_DOUBLE_EQ(f.solver.protrusion_alpha, expected);
    fitted += face ? 1 : 0;
    fading_unfitted += !face && f.weights.fit > 0.0 ? 1 : 0;
  }
  std::cout << "[ E_p tolerance ] solves with a face fitted " << fitted
            << ", with w_f > 0 but no face fitted " << fading_unfitted << "\n";
  EXPECT_GT(fitted, 60);
  EXPECT_GT(fading_unfitted, 5);  // the case the condition is for
}

TEST(StabilizerTest, ProtrusionIsRemovedByBinarySearch) {
  const CameraModel m = Model640x360();
  // Violent shake with a tiny crop: the solver alone cannot stay inside.
  const sim::LandmarkSequence seq(m, ViolentShake());
  StabilizerOptions so;
  so.weights.protrusion = 0.0;  // force the post-solve handling to work
  so.weights.follow = 0.01;
  so.weights.distortion = 0.0;
  const RunResult r = RunSequence(m, seq, so);
  int searches = 0;
  for (const auto& f : r.frames_out) {
    searches += f.flags.protrusion_search;
    if (f.flags.protrusion_search && !f.flags.previous_warp) {
      EXPECT_GT(f.flags.protrusion_search_s, 0.0);
      EXPECT_LE(f.flags.protrusion_search_s, 1.0);
    }
  }
  std::cout << "[ protrusion ] searches " << searches << ", fallbacks "
            << r.fallbacks << ", undefined " << r.undefined << "\n";
  EXPECT_GT(searches, 0);
  EXPECT_EQ(r.undefined, 0);
}

// Where the crop margin runs out, E_p is a stiff wall the solve slides
// along: the default iteration cap lets it finish (paper: "usually converges
// within 3 iterations", which holds only while the margin lasts). The wall
// is made as stiff as the no-face one here (protrusion_alpha_face =
// protrusion_alpha); the face's own, softer tolerance needs fewer long
// solves.
TEST(StabilizerTest, SolvesConvergeWhereTheMarginRunsOut) {
  const CameraModel m = Model640x360();
  const sim::LandmarkSequence seq(m, ViolentShake());
  auto count = [&](int max_iterations, bool stiff, int* long_solves) {
    StabilizerOptions so;
    so.solver.max_iterations = max_iterations;
    so.solver.max_time_s = 10.0;  // the count must not depend on the machine
    if (stiff) so.terms.protrusion_alpha_face = so.terms.protrusion_alpha;
    const RunResult r = RunSequence(m, seq, so);
    int unconverged = 0;
    *long_solves = 0;
    for (const auto& f : r.frames_out) {
      unconverged += f.solver.termination == "NO_CONVERGENCE";
      *long_solves += f.solver.iterations > 10;
    }
    return unconverged;
  };
  const int cap = StabilizerOptions().solver.max_iterations;
  int long_default = 0, long_ten = 0, long_face = 0, long_face_ten = 0;
  const int unconverged_default = count(cap, true, &long_default);
  const int unconverged_ten = count(10, true, &long_ten);
  const int unconverged_face = count(cap, false, &long_face);
  const int unconverged_face_ten = count(10, false, &long_face_ten);
  std::cout << "[ convergence ] stiff wall: unconverged solves, default cap "
            << unconverged_default << " (" << long_default << " took > 10 iterations), cap 10 "
            << unconverged_ten << " of " << seq.frames().size() << "; the face's wall: "
            << unconverged_face << " (" << long_face << "), cap 10 " << unconverged_face_ten
            << "\n";
  EXPECT_GT(unconverged_ten, 10);  // the case exists
  EXPECT_LE(unconverged_default * 10, static_cast<int>(seq.frames().size()));
  EXPECT_LE(unconverged_default * 3, unconverged_ten);
  EXPECT_LE(unconverged_face * 10, static_cast<int>(seq.frames().size()));
  EXPECT_LT(long_face, long_default);
}

// A world-fixed face high in the frame, seen by a shaking rolling-shutter
// camera: its landmarks are read 40 % of a readout before the middle row.
// Where the stabilizer reads the landmark centre (Eq. 1's C in the predicted
// virtual view, and the gyro-compensated centre of the variation measure),
// each landmark must go through its own row's rotation, as E_f moves it.
TEST(StabilizerTest, FaceCentreUsesEachLandmarksRowRotation) {
  const CameraModel m = Model640x360();
  RollingShutterOptions rs;
  rs.readout_time_s = 0.03;
  const RowTiming timing(rs, 360);
  OrientationTimeline tl{OrientationTimelineOptions()};
  // About 2 rad/s peak shake about x and y, a different rate on each.
  auto omega = [](double t) {
    return Eigen::Vector3d(2.0 * std::sin(2 * M_PI * 4.0 * t),
                           1.5 * std::sin(2 * M_PI * 5.3 * t + 1.0), 0.0);
  };
  for (int i = 0; i <= 400; ++i) ASSERT_EQ(tl.AddSample({At(i / 200.0), omega(i / 200.0)}),
                                           SampleResult::kAccepted);
  // The face: 12 points around (0.5, 0.15) as the camera at t = 0 saw them.
  const Eigen::Quaterniond R0 = [&] {
    Eigen::Quaterniond q;
    EXPECT_TRUE(QuerySucceeded(tl.RealRotation(At(0.0), &q)));
    return q;
  }();
  std::vector<Eigen::Vector2d> world;
  for (int k = 0; k < 12; ++k) {
    world.emplace_back(0.5 + 0.04 * std::cos(k * M_PI / 6), 0.15 + 0.05 * std::sin(k * M_PI / 6));
  }
  std::unique_ptr<Stabilizer> stab;
  ASSERT_TRUE(Stabilizer::Create(m, OutputOptions(), StabilizerOptions(), &stab).ok());
  std::vector<StabilizerFrame> out;
  for (int i = 0; i < 12; ++i) {
    const Time stamp = At(0.1 + i / 30.0);
    RowRotations rows;
    ASSERT_TRUE(QuerySucceeded(RowRotations::Build(tl, timing, stamp, 32, &rows)));
    FaceObservation face;
    face.valid = true;
    face.confidence = 1.0;
    for (const Eigen::Vector2d& w : world) {
      // The row the point is read on: the fixed point of row -> rotation.
      double row = 0.5 * 359;
      Eigen::Vector2d p;
      for (int it = 0; it < 10; ++it) {
        ASSERT_TRUE(m.Project(w, rows.At(row), Eigen::Vector2d::Zero(), R0, &p));
        row = std::min(std::max(m.NormalizedToPixel(p).y(), 0.0), 359.0);
      }
      face.landmarks.push_back(p);
      face.landmark_rows.push_back(row);
    }
    ComputeCentreAndScale(&face);
    StabilizerFrame f;
    ASSERT_TRUE(stab->Process(stamp, tl, timing, &face, &f).ok());
    if (i >= 2) {
      // C: in the view predicted from the last two virtual poses.
      const StabilizerFrame &a = out[i - 2], &b = out[i - 1];
      const Eigen::Quaterniond R_pred = ((b.R_v * a.R_v.conjugate()) * b.R_v).normalized();
      const Eigen::Vector2d t_pred = 2.0 * b.t - a.t;
      Eigen::Vector2d per_row = Eigen::Vector2d::Zero(), middle;
      for (size_t k = 0; k < face.landmarks.size(); ++k) {
        Eigen::Vector2d p;
        ASSERT_TRUE(m.Project(face.landmarks[k], R_pred, t_pred, f.rows.At(face.landmark_rows[k]),
                              &p));
        per_row += p / face.landmarks.size();
      }
      ASSERT_TRUE(m.Project(face.centre, R_pred, t_pred, f.R_r, &middle));
      EXPECT_NEAR((f.C - per_row).norm(), 0.0, 1e-9) << "frame " << i;
      // The test means something: the middle row's rotation would be far off.
      EXPECT_GT((middle - per_row).norm() * 640, 2.0) << "frame " << i;
    }
    out.push_back(f);
  }
  // The world-fixed face has no landmark noise: its gyro-compensated centre
  // and scale do not move, so the variation measure stays at 0 and w_f
  // whole. (Through the middle row, the skew swung the centre by pixels per
  // frame and the stretch the scale, and w_f fell to its 0.15 floor.)
  EXPECT_LT(out.back().factors.centre_variation, 1e-6);
  EXPECT_LT(out.back().factors.scale_variation, 1e-6);
  EXPECT_DOUBLE_EQ(out.back().factors.variation_target, 1.0);
}

TEST(StabilizerTest, DeterministicAndResettable) {
  const CameraModel m = Model640x360();
  sim::LandmarkSequenceOptions o = Walk();
  o.duration_s = 2.0;
  const sim::LandmarkSequence seq(m, o);
  const RunResult a = RunSequence(m, seq, StabilizerOptions());
  const RunResult b = RunSequence(m, seq, StabilizerOptions());
  ASSERT_EQ(a.frames_out.size(), b.frames_out.size());
  for (size_t i = 0; i < a.frames_out.size(); ++i) {
    EXPECT_EQ(a.frames_out[i].R_v.coeffs(), b.frames_out[i].R_v.coeffs());
    EXPECT_EQ(a.frames_out[i].t, b.frames_out[i].t);
  }
}

// The evaluation's perfect tracker (steadiface_evaluate --true-head): the
// centre handed over is where that frame's landmarks are taken to be, on
// that frame only. Without the pose-invariant shift (pivot 0) that is the
// same as a face observed there.
TEST(StabilizerTest, TheTrueHeadCentreMovesThatFramesFaceOnly) {
  const CameraModel m = Model640x360();
  sim::LandmarkSequenceOptions o = Walk();
  o.duration_s = 1.0;
  const sim::LandmarkSequence seq(m, o);
  StabilizerOptions so;
  so.dynamic.pose_pivot_depth = 0.0;
  std::unique_ptr<Stabilizer> plain, handed, observed;
  for (auto* s : {&plain, &handed, &observed}) {
    ASSERT_TRUE(Stabilizer::Create(m, OutputOptions(), so, s).ok());
  }
  OrientationTimeline tl{OrientationTimelineOptions()};
  for (const auto& g : seq.gyro()) tl.AddSample(g);
  const int kAt = 10;
  const Eigen::Vector2d shift(0.02, -0.01);
  for (int i = 0; i <= kAt + 3; ++i) {
    const auto& fr = seq.frames()[i];
    FaceObservation moved = fr.observed;
    if (i == kAt) {
      ASSERT_TRUE(moved.valid);
      for (auto& l : moved.landmarks) l += shift;
      moved.centre += shift;
      handed->SetTrueHeadCentre(moved.centre);
    }
    StabilizerFrame fp, fh, fo;
    ASSERT_TRUE(plain->Process(fr.stamp, tl, seq.timing(), &fr.observed, &fp).ok());
    ASSERT_TRUE(handed->Process(fr.stamp, tl, seq.timing(), &fr.observed, &fh).ok());
    ASSERT_TRUE(observed->Process(fr.stamp, tl, seq.timing(), &moved, &fo).ok());
    // (Equal but for rounding: the landmarks are moved by a difference.)
    EXPECT_LT((fh.t - fo.t).norm(), 1e-9) << "frame " << i;
    EXPECT_LT((fh.R_v.coeffs() - fo.R_v.coeffs()).norm(), 1e-9) << "frame " << i;
    if (i == kAt) EXPECT_GT((fh.t - fp.t).norm(), 1e-4) << "the pose follows the centre handed over";
  }
}

TEST(StabilizerTest, ReportsSolverAndEnergies) {
  const CameraModel m = Model640x360();
  sim::LandmarkSequenceOptions o = Walk();
  o.duration_s = 1.0;
  const sim::LandmarkSequence seq(m, o);
  const RunResult r = RunSequence(m, seq, StabilizerOptions());
  const StabilizerFrame& f = r.frames_out.back();
  EXPECT_TRUE(f.solver.ran);
  EXPECT_TRUE(f.solver.usable);
  EXPECT_GE(f.solver.iterations, 0);
  EXPECT_FALSE(f.solver.termination.empty());
  EXPECT_GT(f.energies.fit, 0.0);
  EXPECT_GT(f.energies.total(), 0.0);
  EXPECT_TRUE(f.has_target);
  EXPECT_NEAR(f.solver.final_cost * 2.0, f.energies.total(), 1e-9 + 1e-6 * f.energies.total());
}

TEST(StabilizerTest, RejectsBadOptionsAndStamps) {
  const CameraModel m = Model640x360();
  StabilizerOptions so;
  so.weights.fit = -1;
  std::unique_ptr<Stabilizer> stab;
  Status s = Stabilizer::Create(m, OutputOptions(), so, &stab);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("weights.fit"), std::string::npos) << s.message();
  so = StabilizerOptions();
  so.dynamic.gyro_active_rad_s = 0.0;
  s = Stabilizer::Create(m, OutputOptions(), so, &stab);
  EXPECT_FALSE(s.ok());
  ASSERT_TRUE(Stabilizer::Create(m, OutputOptions(), StabilizerOptions(), &stab).ok());
  OrientationTimeline tl{OrientationTimelineOptions()};
  const RowTiming timing(RollingShutterOptions(), 360);
  StabilizerFrame f;
  // No gyro yet.
  EXPECT_FALSE(stab->Process(Time(FromSeconds(1.0)), tl, timing, nullptr, &f).ok());
  for (int i = 0; i <= 400; ++i) {
    tl.AddSample({Time(FromSeconds(i / 200.0)), Eigen::Vector3d(0.01, 0.02, 0)});
  }
  EXPECT_TRUE(stab->Process(Time(FromSeconds(1.0)), tl, timing, nullptr, &f).ok());
  // Non-increasing stamp.
  EXPECT_FALSE(stab->Process(Time(FromSeconds(0.9)), tl, timing, nullptr, &f).ok());
  stab->Reset();
  EXPECT_TRUE(stab->Process(Time(FromSeconds(0.9)), tl, timing, nullptr, &f).ok());
  EXPECT_TRUE(f.flags.first_frame);
  // A face with NaN landmarks is ignored, not used.
  FaceObservation bad;
  bad.valid = true;
  bad.confidence = 1.0;
  bad.landmarks = {Eigen::Vector2d(NAN, 0.5)};
  bad.centre = Eigen::Vector2d(0.5, 0.5);
  EXPECT_TRUE(stab->Process(Time(FromSeconds(1.0)), tl, timing, &bad, &f).ok());
  EXPECT_FALSE(f.has_target);
  // ... and so is one with a NaN landmark row.
  bad.landmarks = {Eigen::Vector2d(0.5, 0.5)};
  bad.landmark_rows = {NAN};
  EXPECT_TRUE(stab->Process(Time(FromSeconds(1.1)), tl, timing, &bad, &f).ok());
  EXPECT_FALSE(f.has_target);
  EXPECT_TRUE(f.R_v.coeffs().allFinite());
  EXPECT_TRUE(f.R_v.coeffs().allFinite());
}

}  // namespace
}  // namespace steadiface

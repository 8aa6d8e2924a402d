#include "steadiface_core/stabilizer/stabilizer.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <iostream>
#include <random>

#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include "steadiface_core/sim/landmark_sequence.h"
#include "steadiface_core/so3.h"
#include "steadiface_core/stabilizer/distortion_cost.h"
#include "steadiface_core/stabilizer/fitting_cost.h"
#include "steadiface_core/stabilizer/following_cost.h"
#include "steadiface_core/stabilizer/protrusion_cost.h"
#include "steadiface_core/stabilizer/rotation_smoothness_cost.h"
#include "steadiface_core/stabilizer/translation_smoothness_cost.h"

namespace steadiface {
namespace {

CameraModel Model() {
  CameraModel m;
  EXPECT_TRUE(CameraModel::Create(IntrinsicsFromHorizontalFov(640, 360, 1.2),
                                  CameraModelOptions(), &m)
                  .ok());
  return m;
}

// ---------- Cost terms ----------

double Vec8Norm(const double* r) {
  return Eigen::Map<const Eigen::Matrix<double, 8, 1>>(r).norm();
}

// Checks the autodiff Jacobian (mapped to the quaternion's tangent space
// through the manifold's PlusJacobian) against central finite differences
// of the residual along Plus(x, delta) for each tangent direction.
void CheckGradient(ceres::CostFunction* cost_raw,
                   std::vector<const ceres::Manifold*> manifolds,
                   std::vector<double*> params) {
  std::unique_ptr<ceres::CostFunction> cost(cost_raw);
  const int nr = cost->num_residuals();
  const auto& sizes = cost->parameter_block_sizes();
  std::vector<const double*> p(params.begin(), params.end());
  std::vector<double> r0(nr);
  std::vector<std::vector<double>> J(sizes.size());
  std::vector<double*> jac(sizes.size());
  for (size_t b = 0; b < sizes.size(); ++b) {
    J[b].resize(nr * sizes[b]);
    jac[b] = J[b].data();
  }
  ASSERT_TRUE(cost->Evaluate(p.data(), r0.data(), jac.data()));
  for (size_t b = 0; b < sizes.size(); ++b) {
    const ceres::Manifold* m = manifolds[b];
    const int n = sizes[b];
    const int tn = m ? m->TangentSize() : n;
    std::vector<double> P(n * tn, 0.0);
    if (m) {
      m->PlusJacobian(params[b], P.data());
    } else {
      for (int i = 0; i < n; ++i) P[i * n + i] = 1.0;
    }
    for (int k = 0; k < tn; ++k) {
      const double h = 1e-6;
      std::vector<double> xp(n), xm(n), d(tn, 0.0);
      d[k] = h;
      if (m) {
        m->Plus(params[b], d.data(), xp.data());
        d[k] = -h;
        m->Plus(params[b], d.data(), xm.data());
      } else {
        for (int i = 0; i < n; ++i) xp[i] = xm[i] = params[b][i];
        xp[k] += h;
        xm[k] -= h;
      }
      std::vector<double> rp(nr), rm(nr);
      std::vector<const double*> pp = p, pm = p;
      pp[b] = xp.data();
      pm[b] = xm.data();
      ASSERT_TRUE(cost->Evaluate(pp.data(), rp.data(), nullptr));
      ASSERT_TRUE(cost->Evaluate(pm.data(), rm.data(), nullptr));
      for (int row = 0; row < nr; ++row) {
        double analytic = 0.0;
        for (int i = 0; i < n; ++i) analytic += J[b][row * n + i] * P[i * tn + k];
        const double numeric = (rp[row] - rm[row]) / (2 * h);
        EXPECT_NEAR(analytic, numeric, 1e-5 * (1.0 + std::abs(numeric)))
            << "block " << b << " residual " << row << " direction " << k;
      }
    }
  }
}

TEST(CostTermsTest, FittingIsZeroAtOptimumAndGradientMatches) {
  const CameraModel m = Model();
  const Eigen::Quaterniond Rr = ExpSO3(Eigen::Vector3d(0.02, -0.01, 0.03));
  const Eigen::Quaterniond Rv = ExpSO3(Eigen::Vector3d(0.01, 0.02, 0.0));
  const Eigen::Vector2d t(0.01, -0.02), L(0.4, 0.45);
  Eigen::Vector2d H;
  ASSERT_TRUE(m.Project(L, Rv, t, Rr, &H));
  std::unique_ptr<ceres::CostFunction> c(FittingCost::Create(
      L, Rr, H, m.real_focal(), m.virtual_focal(), 3.0));
  double q[4] = {Rv.x(), Rv.y(), Rv.z(), Rv.w()}, tt[2] = {t.x(), t.y()};
  double r[2];
  const double* p[2] = {q, tt};
  ASSERT_TRUE(c->Evaluate(p, r, nullptr));
  EXPECT_NEAR(r[0], 0.0, 1e-12);
  EXPECT_NEAR(r[1], 0.0, 1e-12);
  tt[0] += 0.01;  // off the optimum by 0.01 in x: residual 3 * 0.01
  ASSERT_TRUE(c->Evaluate(p, r, nullptr));
  EXPECT_NEAR(r[0], 0.03, 1e-12);
  ceres::EigenQuaternionManifold qm;
  CheckGradient(FittingCost::Create(L, Rr, H, m.real_focal(), m.virtual_focal(), 3.0),
                {&qm, nullptr}, {q, tt});
}

TEST(CostTermsTest, DistortionLogisticIsFlatBelowThresholdAndGrowsAbove) {
  const Eigen::Quaterniond Rr = ExpSO3(Eigen::Vector3d(0.1, 0.0, 0.0));
  const double thr = 0.08, slope = 150.0;
  std::unique_ptr<ceres::CostFunction> c(DistortionCost::Create(Rr, thr, slope, 1.0));
  auto energy = [&](double angle) {
    const Eigen::Quaterniond Rv = ExpSO3(Eigen::Vector3d(0, 0, angle)) * Rr;
    double q[4] = {Rv.x(), Rv.y(), Rv.z(), Rv.w()}, r[3];
    const double* p[1] = {q};
    EXPECT_TRUE(c->Evaluate(p, r, nullptr));
    return r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
  };
  EXPECT_EQ(energy(0.0), 0.0);  // at the optimum
  // (logistic(Ω) Ω)^2 exactly:
  for (double a : {0.01, 0.05, 0.08, 0.1, 0.2}) {
    const double g = 1.0 / (1.0 + std::exp(-slope * (a - thr)));
    EXPECT_NEAR(energy(a), (g * a) * (g * a), 1e-12) << a;
  }
  EXPECT_LT(energy(0.04), 1e-8);              // ~0 well below the threshold
  EXPECT_GT(energy(0.12), 100 * energy(0.06));  // grows fast above it
  EXPECT_GT(energy(0.2), energy(0.12));
  ceres::EigenQuaternionManifold qm;
  const Eigen::Quaterniond Rv = ExpSO3(Eigen::Vector3d(0.03, 0.05, -0.06)) * Rr;
  double q[4] = {Rv.x(), Rv.y(), Rv.z(), Rv.w()};
  CheckGradient(DistortionCost::Create(Rr, thr, slope, 2.0), {&qm}, {q});
}

TEST(CostTermsTest, FollowingIsSignInvariant) {
  const Eigen::Quaterniond Rr = ExpSO3(Eigen::Vector3d(0.1, -0.2, 0.05));
  std::unique_ptr<ceres::CostFunction> c(FollowingCost::Create(Rr, 1.0));
  double r[4];
  for (double sign : {1.0, -1.0}) {
    double q[4] = {sign * Rr.x(), sign * Rr.y(), sign * Rr.z(), sign * Rr.w()};
    const double* p[1] = {q};
    ASSERT_TRUE(c->Evaluate(p, r, nullptr));
    EXPECT_NEAR(Eigen::Map<Eigen::Vector4d>(r).norm(), 0.0, 1e-15);
  }
  const Eigen::Quaterniond Rv = ExpSO3(Eigen::Vector3d(0.01, 0.0, 0.0)) * Rr;
  double q[4] = {Rv.x(), Rv.y(), Rv.z(), Rv.w()};
  const double* p[1] = {q};
  ASSERT_TRUE(c->Evaluate(p, r, nullptr));
  // |q_v - q_r| = 2 sin(angle / 4) for unit quaternions.
  EXPECT_NEAR(Eigen::Map<Eigen::Vector4d>(r).norm(), 2 * std::sin(0.01 / 4), 1e-12);
  ceres::EigenQuaternionManifold qm;
  CheckGradient(FollowingCost::Create(Rr, 1.5), {&qm}, {q});
}

TEST(CostTermsTest, RotationSmoothnessZeroForConstantVelocity) {
  const Eigen::Quaterniond step = ExpSO3(Eigen::Vector3d(0.0, 0.01, 0.002));
  const Eigen::Quaterniond pp = ExpSO3(Eigen::Vector3d(0.1, 0.0, 0.0));
  const Eigen::Quaterniond p = step * pp;
  const Eigen::Quaterniond cur = step * p;  // constant angular velocity
  std::unique_ptr<ceres::CostFunction> c(RotationSmoothnessCost::Create(
      p, p, p * pp.conjugate(), true, 0.0, 1.0));
  double q[4] = {cur.x(), cur.y(), cur.z(), cur.w()}, r[8];
  const double* params[1] = {q};
  ASSERT_TRUE(c->Evaluate(params, r, nullptr));
  EXPECT_NEAR(Vec8Norm(r), 0.0, 1e-14);
  // C0 at the previous rotation is zero.
  std::unique_ptr<ceres::CostFunction> c0(RotationSmoothnessCost::Create(
      p, p, p * pp.conjugate(), false, 1.0, 1.0));
  double qp[4] = {p.x(), p.y(), p.z(), p.w()};
  params[0] = qp;
  ASSERT_TRUE(c0->Evaluate(params, r, nullptr));
  EXPECT_NEAR(Vec8Norm(r), 0.0, 1e-15);
  ceres::EigenQuaternionManifold qm;
  const Eigen::Quaterniond off = ExpSO3(Eigen::Vector3d(0.02, -0.01, 0.03)) * cur;
  double qo[4] = {off.x(), off.y(), off.z(), off.w()};
  CheckGradient(RotationSmoothnessCost::Create(step * p, p, p * pp.conjugate(), true, 2.0, 3.0),
                {&qm}, {qo});
}

TEST(CostTermsTest, TranslationSmoothnessZeroForConstantVelocity) {
  const Eigen::Vector2d pp(0.01, 0.02), p(0.015, 0.018);
  std::unique_ptr<ceres::CostFunction> c(
      TranslationSmoothnessCost::Create(p, pp, true, 0.0, 1.0));
  double t[2] = {0.02, 0.016}, r[4];  // 2p - pp
  const double* params[1] = {t};
  ASSERT_TRUE(c->Evaluate(params, r, nullptr));
  EXPECT_NEAR(Eigen::Map<Eigen::Vector4d>(r).norm(), 0.0, 1e-15);
  CheckGradient(TranslationSmoothnessCost::Create(p, pp, true, 2.0, 3.0), {nullptr}, {t});
}

TEST(CostTermsTest, ProtrusionIsZeroInsideTheMarginAndPositiveOutside) {
  const CameraModel m = Model();
  OutputGeometry g;
  OutputOptions oo;
  oo.crop_ratio = 0.1;
  ASSERT_TRUE(OutputGeometry::Create(m, oo, &g).ok());
  const ProtrusionGeometry geo(m, g, 8);
  const Eigen::Quaterniond Rr = ExpSO3(Eigen::Vector3d(0.01, 0.02, 0.0));
  std::vector<Eigen::Quaterniond> rows(geo.num_samples(), Rr);
  std::unique_ptr<ceres::CostFunction> c(
      ProtrusionCost::Create(&geo, rows, 3.0, 0.002, 1.0));
  std::vector<double> r(c->num_residuals());
  auto energy = [&](const Eigen::Quaterniond& Rv, const Eigen::Vector2d& t) {
    double q[4] = {Rv.x(), Rv.y(), Rv.z(), Rv.w()}, tt[2] = {t.x(), t.y()};
    const double* p[2] = {q, tt};
    EXPECT_TRUE(c->Evaluate(p, r.data(), nullptr));
    double e = 0;
    for (double v : r) e += v * v;
    return e;
  };
  // Poses inside the margin: zero.
  EXPECT_EQ(energy(Rr, Eigen::Vector2d::Zero()), 0.0);
  EXPECT_EQ(energy(ExpSO3(Eigen::Vector3d(0.0, 0.03, 0.0)) * Rr, {0.0, 0.0}), 0.0);
  EXPECT_EQ(energy(Rr, {0.05, 0.0}), 0.0);
  // Beyond the margin (0.1 of the width = 0.1 / f_r rad): positive, growing.
  const double e1 = energy(ExpSO3(Eigen::Vector3d(0.0, 0.14, 0.0)) * Rr, {0, 0});
  const double e2 = energy(ExpSO3(Eigen::Vector3d(0.0, 0.18, 0.0)) * Rr, {0, 0});
  EXPECT_GT(e1, 0.0);
  EXPECT_GT(e2, e1);
  EXPECT_GT(energy(Rr, {0.12, 0.0}), 0.0);
  // Gradient where it is active.
  ceres::EigenQuaternionManifold qm;
  const Eigen::Quaterniond Rv = ExpSO3(Eigen::Vector3d(0.01, 0.15, 0.02)) * Rr;
  double q[4] = {Rv.x(), Rv.y(), Rv.z(), Rv.w()}, tt[2] = {0.003, 0.0017};
  CheckGradient(ProtrusionCost::Create(&geo, rows, 3.0, 0.002, 1.0), {&qm, nullptr},
                {q, tt});
}

// ---------- Head smoother ----------

TEST(HeadSmootherTest, ExactAgainstBruteForceAndConstraintHolds) {
  HeadSmoother hs{HeadSmootherOptions()};
  const Eigen::Vector2d r(0.1, 0.056);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.15, 0.15);
  for (int trial = 0; trial < 200; ++trial) {
    const Eigen::Vector2d C(0.5 + u(rng), 0.5 + u(rng));
    const Eigen::Vector2d Hp = C + Eigen::Vector2d(u(rng), u(rng));
    const Eigen::Vector2d H = hs.Solve(Hp, C, r);
    EXPECT_LT(std::abs(H.x() - C.x()), r.x());
    EXPECT_LT(std::abs(H.y() - C.y()), r.y());
    // Brute force over a fine grid inside the constraint box.
    double best = std::numeric_limits<double>::infinity();
    for (int i = -300; i <= 300; ++i) {
      for (int j = -300; j <= 300; ++j) {
        const Eigen::Vector2d cand = C + Eigen::Vector2d(r.x() * i / 300.5, r.y() * j / 300.5);
        best = std::min(best, hs.Objective(cand, Hp, C));
      }
    }
    EXPECT_LE(hs.Objective(H, Hp, C), best + 1e-9) << trial;
  }
}

TEST(HeadSmootherTest, StaysForSmallNoiseFollowsLargeMoves) {
  HeadSmoother hs{HeadSmootherOptions()};
  const Eigen::Vector2d r(0.1, 0.056);
  // Landmark centre jittering by +-0.002 around 0.5: H moves far less.
  Eigen::Vector2d H(0.5, 0.5);
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0.0, 0.002);
  double max_dev = 0.0;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector2d C(0.5 + n(rng), 0.5 + n(rng));
    H = hs.Solve(H, C, r);
    max_dev = std::max(max_dev, (H - Eigen::Vector2d(0.5, 0.5)).cwiseAbs().maxCoeff());
  }
  EXPECT_LT(max_dev, 0.002);
  // A 0.2 jump of the face: H follows (and never violates the margin).
  for (int i = 0; i < 60; ++i) {
    H = hs.Solve(H, Eigen::Vector2d(0.7, 0.5), r);
    EXPECT_LT(std::abs(H.x() - 0.7), r.x());
  }
  EXPECT_NEAR(H.x(), 0.7, 0.005);
}

// ---------- Stabilizer on ground-truth sequences ----------

struct Jitter {
  double head_px = 0.0, background_px = 0.0;
};

// RMS of x - (centred moving average over `win` frames): a ~fps/win Hz
// high-pass, on the frames where the whole window exists.
double HighPassRms(const std::vector<Eigen::Vector2d>& x, int win) {
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

RunResult RunSequence(const CameraModel& m, const sim::LandmarkSequence& seq,
              StabilizerOptions so) {
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

sim::LandmarkSequenceOptions Walk() {
  sim::LandmarkSequenceOptions o;
  o.duration_s = 6.0;
  o.camera.shake_rms_rad = 0.012;
  o.camera.translation_rms_m = 0.002;
  o.shutter.readout_time_s = 0.02;
  o.landmark_noise_px = 0.7;
  o.gyro_noise = 0.003;
  return o;
}

void Print(const char* name, const RunResult& r) {
  std::cout << "[ " << name << " ] head jitter in " << r.input.head_px
            << " px -> " << r.output.head_px << " px; background "
            << r.input.background_px << " -> " << r.output.background_px
            << " px; undefined frames " << r.undefined << "/" << r.frames
            << "\n";
}

TEST(StabilizerTest, BeatsGyroOnlyOnHeadJitterWalking) {
  const CameraModel m = Model();
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
  // is gyro-only's residual head jitter (~6 px here), not zero.
  EXPECT_LE(gyro.output.background_px, 0.1 * gyro.input.background_px);
  EXPECT_LE(full.output.background_px, 0.75 * full.input.background_px);
  EXPECT_LE(full.output.background_px, 1.1 * gyro.output.head_px);
  EXPECT_EQ(full.undefined, 0);
  EXPECT_EQ(gyro.undefined, 0);
}

// The background layer (issue 15's second virtual camera) is exactly the
// gyro-only pose, solved alongside the face-following one with its own
// state; turning it on leaves the face-following layer untouched. The face
// drops out for a while, so the layers must stay apart through a loss.
TEST(StabilizerTest, BackgroundLayerIsExactlyTheGyroOnlyPoseAndLeavesTheSubjectAlone) {
  const CameraModel m = Model();
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

TEST(StabilizerTest, StillCameraGivesStillVirtualCamera) {
  const CameraModel m = Model();
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
  const CameraModel m = Model();
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

TEST(StabilizerTest, ProtrusionIsRemovedByBinarySearch) {
  const CameraModel m = Model();
  // Violent shake with a tiny crop: the solver alone cannot stay inside.
  sim::LandmarkSequenceOptions o = Walk();
  o.camera.shake_rms_rad = 0.03;
  o.duration_s = 3.0;
  const sim::LandmarkSequence seq(m, o);
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

TEST(StabilizerTest, DeterministicAndResettable) {
  const CameraModel m = Model();
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

TEST(StabilizerTest, ReportsSolverAndEnergies) {
  const CameraModel m = Model();
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
  const CameraModel m = Model();
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
  stab->reset();
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
  const CameraModel m = Model();
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
  const CameraModel m = Model();
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
  const CameraModel m = Model();
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

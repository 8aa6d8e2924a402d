// The stabilizer's building blocks, each against a closed form: every
// paper term's cost functor (zero at its optimum, autodiff Jacobian against
// finite differences on the quaternion manifold) and the head smoother of
// Eq. 1 (exact against brute force). The whole stabilizer on ground-truth
// sequences is in stabilizer_test.cc.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <ceres/autodiff_cost_function.h>
#include <gtest/gtest.h>

#include "steadiface_core/common/ceres_compat.h"
#include "steadiface_core/common/so3.h"
#include "steadiface_core/stabilizer/distortion_cost.h"
#include "steadiface_core/stabilizer/fitting_cost.h"
#include "steadiface_core/stabilizer/following_cost.h"
#include "steadiface_core/stabilizer/head_smoother.h"
#include "steadiface_core/stabilizer/protrusion_cost.h"
#include "steadiface_core/stabilizer/rotation_smoothness_cost.h"
#include "steadiface_core/stabilizer/stabilizer_options.h"
#include "steadiface_core/stabilizer/stall_tolerant_solve.h"
#include "steadiface_core/stabilizer/translation_smoothness_cost.h"
#include "test_util.h"

namespace steadiface {
namespace {

using ceres_compat::QuaternionTangentSpace;
using testing_util::Model640x360;
// ---------- Cost terms ----------

double Vec8Norm(const double* r) {
  return Eigen::Map<const Eigen::Matrix<double, 8, 1>>(r).norm();
}

// Checks the autodiff Jacobian (mapped to the quaternion's tangent space
// through the manifold's PlusJacobian) against central finite differences
// of the residual along Plus(x, delta) for each tangent direction.
void CheckGradient(ceres::CostFunction* cost_raw,
                   std::vector<const QuaternionTangentSpace*> manifolds,
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
    const QuaternionTangentSpace* m = manifolds[b];
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
  const CameraModel m = Model640x360();
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
  QuaternionTangentSpace qm;
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
  QuaternionTangentSpace qm;
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
  QuaternionTangentSpace qm;
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
  QuaternionTangentSpace qm;
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
  const CameraModel m = Model640x360();
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
  QuaternionTangentSpace qm;
  const Eigen::Quaterniond Rv = ExpSO3(Eigen::Vector3d(0.01, 0.15, 0.02)) * Rr;
  double q[4] = {Rv.x(), Rv.y(), Rv.z(), Rv.w()}, tt[2] = {0.003, 0.0017};
  CheckGradient(ProtrusionCost::Create(&geo, rows, 3.0, 0.002, 1.0), {&qm, nullptr},
                {q, tt});
}

// E_p's tolerance follows the fitting weight: the stiff no-face wall at
// w_f 0, the face's at the nominal w_f and above, linear between.
TEST(CostTermsTest, ProtrusionToleranceFollowsTheFittingWeight) {
  TermOptions t;
  t.protrusion_alpha = 0.002;
  t.protrusion_alpha_face = 0.02;
  EXPECT_DOUBLE_EQ(ProtrusionAlpha(t, 0.0, 100.0), 0.002);
  EXPECT_DOUBLE_EQ(ProtrusionAlpha(t, 25.0, 100.0), 0.0065);
  EXPECT_DOUBLE_EQ(ProtrusionAlpha(t, 100.0, 100.0), 0.02);
  EXPECT_DOUBLE_EQ(ProtrusionAlpha(t, 400.0, 100.0), 0.02);
  // No fitting term or no usable weight: the no-face wall.
  EXPECT_DOUBLE_EQ(ProtrusionAlpha(t, 50.0, 0.0), 0.002);
  EXPECT_DOUBLE_EQ(ProtrusionAlpha(t, std::nan(""), 100.0), 0.002);
  // Out of range is refused.
  StabilizerOptions o;
  EXPECT_TRUE(ValidateStabilizerOptions(o).ok());
  o.terms.protrusion_alpha_face = 0.0;
  const Status bad = ValidateStabilizerOptions(o);
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message().find("protrusion_alpha_face"), std::string::npos) << bad.message();
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

// Without the constraint (an infinite margin), the exact solution against
// brute force over a box wide enough to hold the unconstrained optimum; and
// a target far from C is not pulled into the crop-margin box in one step.
TEST(HeadSmootherTest, InfiniteMarginDropsTheConstraint) {
  HeadSmoother hs{HeadSmootherOptions()};
  const double inf = std::numeric_limits<double>::infinity();
  const Eigen::Vector2d unbounded(inf, inf);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  for (int trial = 0; trial < 100; ++trial) {
    const Eigen::Vector2d C(0.5 + u(rng), 0.5 + u(rng));
    const Eigen::Vector2d Hp = C + Eigen::Vector2d(u(rng), u(rng));
    const Eigen::Vector2d H = hs.Solve(Hp, C, unbounded);
    ASSERT_TRUE(H.allFinite());
    // The optimum lies between C and Hp on each axis.
    const Eigen::Vector2d lo = C.cwiseMin(Hp), hi = C.cwiseMax(Hp);
    double best = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 400; ++i) {
      for (int j = 0; j <= 400; ++j) {
        const Eigen::Vector2d cand(lo.x() + (hi.x() - lo.x()) * i / 400.0,
                                   lo.y() + (hi.y() - lo.y()) * j / 400.0);
        best = std::min(best, hs.Objective(cand, Hp, C));
      }
    }
    EXPECT_LE(hs.Objective(H, Hp, C), best + 1e-9) << trial;
  }
  // H_prev 0.3 from C, beyond a 0.1 margin: bounded, H must jump into the
  // box; unbounded, it moves by Eq. 1's own step (w2/d_ref^2 against w1).
  const Eigen::Vector2d C(0.5, 0.5), Hp(0.8, 0.5), r(0.1, 0.056);
  EXPECT_LT(hs.Solve(Hp, C, r).x(), 0.6);
  const double k = 1.0 / (0.03 * 0.03), w1 = 5000.0;
  EXPECT_NEAR(hs.Solve(Hp, C, unbounded).x(), 0.5 + 0.3 * w1 / (w1 + k), 1e-12);
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

// Rosenbrock's valley: several steps from (-1.2, 1) to (1, 1).
struct Rosenbrock {
  template <typename T>
  bool operator()(const T* x, T* r) const {
    r[0] = T(1.0) - x[0];
    r[1] = T(10.0) * (x[1] - x[0] * x[0]);
    return true;
  }
};

// The solver's wall-time cap runs out before the first step (a stall): plain
// Ceres returns the starting point; StallTolerantSolve puts the parameters
// back and reruns, giving exactly the uncapped solve.
TEST(StallTolerantSolveTest, ACapThatRunsOutBeforeTheFirstStepIsRerun) {
  auto solve = [](double cap, bool tolerant, bool* rerun, ceres::Solver::Summary* summary) {
    double x[2] = {-1.2, 1.0};
    ceres::Problem problem;
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<Rosenbrock, 2, 2>(new Rosenbrock), nullptr, x);
    ceres::Solver::Options o;
    o.linear_solver_type = ceres::DENSE_QR;
    o.max_num_iterations = 50;
    o.max_solver_time_in_seconds = cap;
    o.logging_type = ceres::SILENT;
    *rerun = false;
    if (tolerant) {
      *rerun = StallTolerantSolve(
          o, &problem, [&x] { x[0] = -1.2, x[1] = 1.0; }, summary);
    } else {
      ceres::Solve(o, &problem, summary);
    }
    return Eigen::Vector2d(x[0], x[1]);
  };
  bool rerun = false;
  ceres::Solver::Summary s_free, s_stalled, s_tolerant, s_tolerant_free;
  const Eigen::Vector2d free = solve(1e6, false, &rerun, &s_free);
  EXPECT_EQ(s_free.termination_type, ceres::CONVERGENCE);
  EXPECT_NEAR(free.x(), 1.0, 1e-6);
  EXPECT_NEAR(free.y(), 1.0, 1e-6);
  // The stall, as plain Ceres sees it: no step, the starting point back.
  const Eigen::Vector2d stalled = solve(1e-12, false, &rerun, &s_stalled);
  EXPECT_EQ(s_stalled.termination_type, ceres::NO_CONVERGENCE);
  EXPECT_EQ(stalled, Eigen::Vector2d(-1.2, 1.0));
  // Tolerant: rerun, and bit for bit the uncapped answer.
  const Eigen::Vector2d tolerant = solve(1e-12, true, &rerun, &s_tolerant);
  EXPECT_TRUE(rerun);
  EXPECT_EQ(s_tolerant.termination_type, ceres::CONVERGENCE);
  EXPECT_EQ(tolerant, free);
  // A cap that does not run out changes nothing.
  const Eigen::Vector2d untouched = solve(1e6, true, &rerun, &s_tolerant_free);
  EXPECT_FALSE(rerun);
  EXPECT_EQ(untouched, free);
}

}  // namespace
}  // namespace steadiface

#include "visual/rotation_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Dense>

#include "steadiface_core/common/so3.h"

namespace steadiface {
namespace visual {
namespace {

// The scene point's bearing in the second frame, Exp(-phi) b1.
Eigen::Vector3d Moved(const Motion& m, const BearingPair& p) {
  return ExpSO3(-PairTurn(m, p)) * p.b1;
}

double ErrorPx(const Motion& omega, const BearingPair& p, double focal_px) {
  return (Predict(omega, p) - p.n2).norm() * focal_px;
}

std::vector<int> Inliers(const std::vector<BearingPair>& pairs,
                         const Motion& omega, double focal_px,
                         double threshold_px) {
  std::vector<int> in;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (ErrorPx(omega, pairs[i], focal_px) < threshold_px)
      in.push_back(static_cast<int>(i));
  }
  return in;
}

using Matrix9 = Eigen::Matrix<double, 9, 9>;

// The Gauss-Newton normal equations of the pairs `in` at `m`, each pair's
// rows weighted by `weights` (empty: 1 each), priors included. The
// Jacobian takes the rotation as small (b2 + b2 x dphi for a change dphi):
// one frame's turn is a few degrees, and the residuals themselves are
// exact.
void NormalEquations(const std::vector<BearingPair>& pairs, const std::vector<int>& in,
                     const std::vector<double>& weights, const Motion& m,
                     const MotionPrior& prior, Matrix9* JtJ, Motion* Jtr) {
  JtJ->setZero();
  Jtr->setZero();
  for (int i : in) {
    const BearingPair& p = pairs[i];
    const Eigen::Vector3d b2 = Moved(m, p);
    const Eigen::Vector2d r = b2.head<2>() / b2.z() - p.n2;
    Eigen::Matrix<double, 2, 3> Jp;  // d(x/z, y/z) / d b2
    Jp << 1.0 / b2.z(), 0.0, -b2.x() / (b2.z() * b2.z()), 0.0, 1.0 / b2.z(),
        -b2.y() / (b2.z() * b2.z());
    Eigen::Matrix3d skew;  // d b2 / d phi, with b2 = Exp(-phi) b1
    skew << 0.0, -b2.z(), b2.y(), b2.z(), 0.0, -b2.x(), -b2.y(), b2.x(), 0.0;
    const Eigen::Matrix<double, 2, 3> Jphi = Jp * skew;
    Eigen::Matrix<double, 2, 9> J;
    J << p.c * Jphi, p.d * Jphi, p.e * Jphi;
    const double w = weights.empty() ? 1.0 : weights[i];
    *JtJ += w * J.transpose() * J;
    *Jtr += w * J.transpose() * r;
  }
  // The priors: alpha |alpha|^2 + beta |beta|^2.
  JtJ->diagonal().segment<3>(3).array() += prior.alpha;
  Jtr->segment<3>(3) += prior.alpha * m.segment<3>(3);
  JtJ->diagonal().tail<3>().array() += prior.beta;
  Jtr->tail<3>() += prior.beta * m.tail<3>();
}

// Gauss-Newton on the pairs `in` (9 unknowns), each weighted by `weights`
// (empty: 1 each), damped a little so that a triple's nearly singular
// system stays bounded.
Motion Refine(const std::vector<BearingPair>& pairs, const std::vector<int>& in,
              const std::vector<double>& weights, Motion m, int iterations,
              const MotionPrior& prior) {
  for (int iter = 0; iter < iterations; ++iter) {
    Matrix9 JtJ;
    Motion Jtr;
    NormalEquations(pairs, in, weights, m, prior, &JtJ, &Jtr);
    JtJ.diagonal() *= 1.0 + 1e-9;
    JtJ.diagonal().array() += 1e-12;
    const Motion delta = JtJ.ldlt().solve(-Jtr);
    if (!delta.allFinite()) break;
    m += delta;
    if (delta.norm() < 1e-7) break;
  }
  return m;
}

// The standard error of the camera's turn across the inliers' mean pair
// (their mean c, d, e: about one frame interval) [px at the focal length],
// its largest direction: sigma^2 J (JtJ)^-1 J^T with the inliers' residual
// sigma, at least kMinSigmaPx.
double TurnSigmaPx(const std::vector<BearingPair>& pairs,
                   const std::vector<int>& in, const Motion& m,
                   const MotionPrior& prior, double rms_px) {
  constexpr double kMinSigmaPx = 0.25;  // a residual this small is luck
  Matrix9 JtJ;
  Motion Jtr;
  NormalEquations(pairs, in, {}, m, prior, &JtJ, &Jtr);
  double c = 0.0, d = 0.0, e = 0.0;
  for (int i : in) {
    c += pairs[i].c / in.size();
    d += pairs[i].d / in.size();
    e += pairs[i].e / in.size();
  }
  Eigen::Matrix<double, 3, 9> J;
  J << c * Eigen::Matrix3d::Identity(), d * Eigen::Matrix3d::Identity(),
      e * Eigen::Matrix3d::Identity();
  const Eigen::Matrix<double, 9, 3> X = JtJ.ldlt().solve(J.transpose());
  const Eigen::Matrix3d cov = J * X;
  const double sigma = std::max(rms_px, kMinSigmaPx);
  const double largest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov)
                             .eigenvalues()
                             .maxCoeff();
  const double s = sigma * std::sqrt(std::max(largest, 0.0));
  return std::isfinite(s) ? s : std::numeric_limits<double>::infinity();
}

}  // namespace

Eigen::Vector3d PairTurn(const Motion& m, const BearingPair& p) {
  return p.c * m.head<3>() + p.d * m.segment<3>(3) + p.e * m.tail<3>();
}

Eigen::Vector2d Predict(const Motion& m, const BearingPair& p) {
  const Eigen::Vector3d b2 = Moved(m, p);
  return b2.head<2>() / b2.z();
}

namespace {

// RANSAC over triples of the pairs: the hypothesis whose inliers have the
// most summed weight. Adaptive: it stops once a hypothesis with the best's
// share of inliers would have been drawn with 99 % probability, after at
// least kMinIterations.
struct Hypothesis {
  Motion motion = Motion::Zero();
  std::vector<int> inliers;
  double support = 0.0;
};

Hypothesis Ransac(const std::vector<BearingPair>& pairs, const std::vector<double>& weights,
                  double focal_px, double threshold_px, int iterations, const MotionPrior& prior,
                  std::mt19937_64* rng) {
  Hypothesis best;
  const int n = static_cast<int>(pairs.size());
  std::uniform_int_distribution<int> pick(0, n - 1);
  constexpr int kMinIterations = 24;
  int needed = iterations;
  for (int it = 0; it < needed; ++it) {
    const int a = pick(*rng);
    const int b = (a + 1 + pick(*rng) % (n - 1)) % n;
    int c = pick(*rng);
    if (c == a || c == b) continue;
    const Motion m = Refine(pairs, {a, b, c}, {}, Motion::Zero(), 3, prior);
    if (!m.allFinite()) continue;
    std::vector<int> in = Inliers(pairs, m, focal_px, threshold_px);
    double w = 0.0;
    for (int i : in) w += weights.empty() ? 1.0 : weights[i];
    if (w <= best.support) continue;
    best = {m, std::move(in), w};
    const double share = static_cast<double>(best.inliers.size()) / n;
    const double miss = 1.0 - share * share * share;
    needed = std::min(needed, miss < 1e-9 ? std::max(it + 1, kMinIterations)
                                          : std::max(kMinIterations,
                                                     static_cast<int>(std::ceil(
                                                         std::log(0.01) / std::log(miss)))));
  }
  return best;
}

}  // namespace

bool FitMotion(const std::vector<BearingPair>& pairs, const std::vector<double>& weights,
               double focal_px, double threshold_px, int iterations, const MotionPrior& prior,
               uint64_t seed, RotationFit* fit) {
  const int n = static_cast<int>(pairs.size());
  if (n < 3) return false;
  auto support = [&weights](const std::vector<int>& in) {
    double w = 0.0;
    for (int i : in) w += weights.empty() ? 1.0 : weights[i];
    return w;
  };
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  const double total = support(all);
  std::mt19937_64 rng(seed);
  Hypothesis h = Ransac(pairs, weights, focal_px, threshold_px, iterations, prior, &rng);
  std::vector<int> best = h.inliers;
  Motion best_m = h.motion;
  if (best.size() < 3) return false;
  for (int round = 0; round < 2; ++round) {
    best_m = Refine(pairs, best, weights, best_m, 5, prior);
    best = Inliers(pairs, best_m, focal_px, threshold_px);
    if (best.size() < 3) return false;
  }
  double ss = 0.0;
  for (int i : best) ss += std::pow(ErrorPx(best_m, pairs[i], focal_px), 2);
  fit->motion = best_m;
  fit->inliers = best;
  fit->rms_px = std::sqrt(ss / best.size());
  fit->support = support(best) / total;
  fit->turn_sigma_px = TurnSigmaPx(pairs, best, best_m, prior, fit->rms_px);
  return true;
}

}  // namespace visual
}  // namespace steadiface

#pragma once

// The calibrator's refinement: the track cost Ceres minimizes, the two-pass
// solve over the tracks, the residuals' spread and the parameters'
// 1-sigma from the covariance. Private to src/calibration/.

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include "steadiface_core/calibration/calibrator.h"
#include "steadiface_core/calibration/gyro_integral.h"
#include "steadiface_core/camera/lens_distortion.h"
#include "steadiface_core/common/ceres_compat.h"
#include "steadiface_core/common/percentile.h"

namespace steadiface {
namespace calibration_internal {

// One track between two frames: the ray of frame a moves by the camera's
// rotation between the two rows' times, predicted by the gyro:
//   theta = R_cam_imu (I(t_b - offset) - I(t_a - offset) - bias (t_b - t_a))
//   ray_b = Exp(-theta) ray_a          (R_r = C^T, C' = C [omega]x)
// Residual (2): the predicted pixel minus the tracked one [px].
struct TrackCost {
  TrackCost(const GyroIntegral* g, const CameraIntrinsics& k,
            const Eigen::Vector3d& ray_a, const Eigen::Vector2d& px_b,
            double sa, double fa, double sb, double fb)
      : g_(g),
        k_(k),
        ray_a_(ray_a),
        px_b_(px_b),
        sa_(sa),
        fa_(fa),
        sb_(sb),
        fb_(fb) {}

  template <typename T>
  bool operator()(const T* q, const T* offset, const T* readout, const T* bias,
                  T* r) const {
    const T ta = T(sa_) + readout[0] * T(fa_) - offset[0];
    const T tb = T(sb_) + readout[0] * T(fb_) - offset[0];
    const Eigen::Matrix<T, 3, 1> b(bias[0], bias[1], bias[2]);
    const Eigen::Matrix<T, 3, 1> dI = g_->At(tb) - g_->At(ta) - b * (tb - ta);
    const Eigen::Map<const Eigen::Quaternion<T>> R(q);
    const Eigen::Matrix<T, 3, 1> theta = -(R * dI);
    const T ray[3] = {T(ray_a_.x()), T(ray_a_.y()), T(ray_a_.z())};
    T rb[3];
    ceres::AngleAxisRotatePoint(theta.data(), ray, rb);
    if (!(rb[2] > T(1e-6))) return false;
    r[0] = T(k_.fx) * rb[0] / rb[2] + T(k_.cx) - T(px_b_.x());
    r[1] = T(k_.fy) * rb[1] / rb[2] + T(k_.cy) - T(px_b_.y());
    return true;
  }

  static ceres::CostFunction* Create(const GyroIntegral* g,
                                     const CameraIntrinsics& k,
                                     const Eigen::Vector3d& ray_a,
                                     const Eigen::Vector2d& px_b, double sa,
                                     double fa, double sb, double fb) {
    // Residuals: 2; parameters: R_cam_imu (4), offset (1), readout (1), bias
    // (3).
    return new ceres::AutoDiffCostFunction<TrackCost, 2, 4, 1, 1, 3>(
        new TrackCost(g, k, ray_a, px_b, sa, fa, sb, fb));
  }

  const GyroIntegral* g_;
  const CameraIntrinsics k_;
  const Eigen::Vector3d ray_a_;
  const Eigen::Vector2d px_b_;
  const double sa_, fa_, sb_,
      fb_;  // stamp [s since the gyro origin], readout share
};

// The parameters' 1-sigma from Ceres' covariance scaled by the residuals'
// spread sigma2; false when it cannot be computed.
inline bool Sigmas(ceres::Problem* problem, double* q, double* offset, double* readout, double* bias,
            double sigma2, const CalibratorOptions& o, CalibrationResult* res) {
  ceres::Covariance::Options co;
  ceres::Covariance cov(co);
  std::vector<std::pair<const double*, const double*>> blocks = {
      {q, q}, {offset, offset}, {readout, readout}, {bias, bias}};
  if (!cov.Compute(blocks, problem)) return false;
  double cq[9], co1[1], cr[1], cb[9];
  cov.GetCovarianceBlockInTangentSpace(q, q, cq);
  cov.GetCovarianceBlock(offset, offset, co1);
  if (o.estimate_readout) cov.GetCovarianceBlock(readout, readout, cr);
  if (o.estimate_bias) cov.GetCovarianceBlock(bias, bias, cb);
  const Eigen::Map<Eigen::Matrix3d> Cq(cq);
  // The quaternion's tangent (ceres_compat.h): Plus(x, delta) turns by 2 |delta|.
  res->rotation_sigma_deg =
      2.0 * std::sqrt(std::max(0.0, sigma2 * Cq.eigenvalues().real().maxCoeff())) * 180.0 / M_PI;
  res->time_offset_sigma_s = std::sqrt(std::max(0.0, sigma2 * co1[0]));
  res->readout_sigma_s = o.estimate_readout ? std::sqrt(std::max(0.0, sigma2 * cr[0])) : 0.0;
  if (o.estimate_bias) {
    for (int i = 0; i < 3; ++i) res->bias_sigma(i) = std::sqrt(std::max(0.0, sigma2 * cb[4 * i]));
  }
  return true;
}

// The median track residual at a given mounting, offset and readout, no
// bias (the "before" of the report).
template <typename Obs, typename Residual>
double MedianResidual(const std::vector<Obs>& obs, const Residual& residual_of,
                      const Eigen::Quaterniond& R, double offset_s, double readout_s) {
  double q0[4], off0[1] = {offset_s}, ro0[1] = {readout_s}, b0[3] = {0, 0, 0};
  Eigen::Map<Eigen::Quaterniond> q0_map(q0);
  q0_map = R;
  std::vector<double> r;
  for (const Obs& ob : obs) r.push_back(residual_of(ob, q0, off0, ro0, b0));
  return Percentile(r, 0.5);
}

// Ceres over the tracks, twice: the second pass without the tracks whose
// residual exceeds 3 px after the first. Returns the last problem (for the
// covariance); the solver's brief report into *report.
template <typename Obs, typename MakeCost, typename Residual>
std::unique_ptr<ceres::Problem> SolveTracks(const std::vector<Obs>& obs, const MakeCost& make_cost,
                                            const Residual& residual_of, double period,
                                            const CalibratorOptions& o, double* q, double* offset,
                                            double* readout, double* bias, std::vector<bool>* keep,
                                            std::string* report) {
  std::unique_ptr<ceres::Problem> problem;
  for (int pass = 0; pass < 2; ++pass) {
    problem.reset(new ceres::Problem);
    for (size_t j = 0; j < obs.size(); ++j) {
      if (!(*keep)[j]) continue;
      problem->AddResidualBlock(make_cost(obs[j]), new ceres::CauchyLoss(o.loss_scale_px), q,
                                offset, readout, bias);
    }
    ceres_compat::SetQuaternionManifold(problem.get(), q);
    problem->SetParameterLowerBound(readout, 0, 0.0);
    problem->SetParameterUpperBound(readout, 0, std::max(1e-4, period));
    if (!o.estimate_readout) problem->SetParameterBlockConstant(readout);
    if (!o.estimate_bias) problem->SetParameterBlockConstant(bias);
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = 50;
    so.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(so, problem.get(), &summary);
    *report = summary.BriefReport();
    if (pass == 0) {
      for (size_t j = 0; j < obs.size(); ++j) {
        (*keep)[j] = residual_of(obs[j], q, offset, readout, bias) <= 3.0;
      }
    }
  }
  return problem;
}

// The median residual over every track into *median, and the kept tracks'
// residual variance per coordinate (2 per track, 9 parameters), which
// scales the covariance.
template <typename Obs, typename Residual>
double ResidualSpread(const std::vector<Obs>& obs, const Residual& residual_of,
                      const std::vector<bool>& keep, const double* q, const double* offset,
                      const double* readout, const double* bias, double* median) {
  std::vector<double> r;
  double sq = 0.0;
  int used = 0;
  for (size_t j = 0; j < obs.size(); ++j) {
    const double e = residual_of(obs[j], q, offset, readout, bias);
    r.push_back(e);
    if (keep[j]) {
      sq += e * e;
      ++used;
    }
  }
  *median = Percentile(r, 0.5);
  return used > 9 ? sq / (2.0 * used - 9.0) : 1.0;
}

}  // namespace calibration_internal
}  // namespace steadiface

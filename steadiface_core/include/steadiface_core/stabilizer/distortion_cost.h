#pragma once

#include <cmath>

#include <ceres/autodiff_cost_function.h>

#include "steadiface_core/stabilizer/quaternion_residuals.h"

namespace steadiface {

/// Distortion term E_d (paper §4.2, Eq. 7):
///
///   E_d(R_v) = ( logistic(Ω(R_v, R_r)) · Ω(R_v, R_r) )^2
///   logistic(Ω) = 1 / (1 + exp(-slope (Ω - threshold)))
///
/// Ω is the angle between the virtual and the real rotation. The penalty is
/// ~0 while Ω stays below `threshold` and grows quickly above it. The
/// residual is the rotation vector of R_v R_r^-1 scaled by
/// sqrt(w_d) logistic(Ω), whose norm is sqrt(w_d) logistic(Ω) Ω (so its
/// square is exactly w_d E_d) and which stays differentiable at Ω = 0.
///
/// Parameters: R_v quaternion [4]. Residuals [3] [rad].
class DistortionCost {
 public:
  DistortionCost(const Eigen::Quaterniond& R_r, double threshold_rad,
                 double slope_per_rad, double scale)
      : R_r_(R_r),
        threshold_(threshold_rad),
        slope_(slope_per_rad),
        scale_(scale) {}

  /// Numerically stable for any argument (no exp overflow, so no NaN
  /// derivatives far from the threshold).
  template <typename T>
  static T Logistic(const T& omega, double threshold, double slope) {
    using std::exp;
    const T x = T(slope) * (omega - T(threshold));
    if (x < T(0.0)) {
      const T e = exp(x);
      return e / (T(1.0) + e);
    }
    return T(1.0) / (T(1.0) + exp(-x));
  }

  template <typename T>
  bool operator()(const T* q, T* residuals) const {
    using std::sqrt;
    const Eigen::Quaternion<T> R_v = QuaternionFromBlock(q);
    const Eigen::Matrix<T, 3, 1> phi =
        RotationVector<T>(R_v * R_r_.conjugate().cast<T>());
    const T omega2 = phi.squaredNorm();
    const T omega = omega2 > T(1e-20) ? sqrt(omega2) : T(0.0);
    const T g = T(scale_) * Logistic<T>(omega, threshold_, slope_);
    for (int i = 0; i < 3; ++i) residuals[i] = g * phi(i);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Quaterniond& R_r,
                                     double threshold_rad, double slope,
                                     double scale) {
    return new ceres::AutoDiffCostFunction<DistortionCost, 3, 4>(
        new DistortionCost(R_r, threshold_rad, slope, scale));
  }

 private:
  const Eigen::Quaterniond R_r_;
  const double threshold_, slope_, scale_;
};

}  // namespace steadiface

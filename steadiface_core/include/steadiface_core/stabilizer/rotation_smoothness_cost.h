#pragma once

#include <ceres/autodiff_cost_function.h>

#include "steadiface_core/stabilizer/quaternion_residuals.h"

namespace steadiface {

/// Rotation smoothness term E_r (paper §4.2, Eq. 9), C0 and C1:
///
///   E_r(R_v) = w_r,C0 || R_v - R_v,-1 ||^2
///            + w_r,C1 || R_v R_v,-1^-1 - R_v,-1 R_v,-2^-1 ||^2
///
/// Quaternion differences, each side sign-aligned to its reference (the
/// previous virtual rotation, and the previous frame-to-frame change).
/// Without a frame before the previous one, the C1 residuals are 0.
///
/// Parameters: R_v quaternion [4].
/// Residuals [8]: sqrt(w_r,C0) (q_v - q_v,-1) [4],
///                sqrt(w_r,C1) (q_v q_v,-1^-1 - q_v,-1 q_v,-2^-1) [4].
class RotationSmoothnessCost {
 public:
  RotationSmoothnessCost(const Eigen::Quaterniond& prev,
                         const Eigen::Quaterniond& prev_delta, bool has_c1,
                         double scale_c0, double scale_c1)
      : prev_(prev),
        prev_delta_(prev_delta),
        has_c1_(has_c1),
        scale_c0_(scale_c0),
        scale_c1_(scale_c1) {}

  template <typename T>
  bool operator()(const T* q, T* residuals) const {
    const Eigen::Quaternion<T> R_v = QuaternionFromBlock(q);
    const Eigen::Matrix<T, 4, 1> c0 = AlignedCoeffs<T>(R_v, prev_);
    for (int i = 0; i < 4; ++i) {
      residuals[i] = T(scale_c0_) * (c0(i) - T(prev_.coeffs()(i)));
    }
    if (!has_c1_) {
      for (int i = 4; i < 8; ++i) residuals[i] = T(0.0);
      return true;
    }
    const Eigen::Quaternion<T> delta = R_v * prev_.conjugate().cast<T>();
    const Eigen::Matrix<T, 4, 1> c1 = AlignedCoeffs<T>(delta, prev_delta_);
    for (int i = 0; i < 4; ++i) {
      residuals[4 + i] = T(scale_c1_) * (c1(i) - T(prev_delta_.coeffs()(i)));
    }
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Quaterniond& prev,
                                     const Eigen::Quaterniond& prev_delta,
                                     bool has_c1, double scale_c0,
                                     double scale_c1) {
    return new ceres::AutoDiffCostFunction<RotationSmoothnessCost, 8, 4>(
        new RotationSmoothnessCost(prev, prev_delta, has_c1, scale_c0,
                                   scale_c1));
  }

 private:
  const Eigen::Quaterniond prev_, prev_delta_;
  const bool has_c1_;
  const double scale_c0_, scale_c1_;
};

}  // namespace steadiface

#pragma once

#include <ceres/autodiff_cost_function.h>

#include "steadiface_core/stabilizer/quaternion_residuals.h"

namespace steadiface {

/// Rotation following term E_o (paper §4.2, Eq. 8):
///
///   E_o(R_v) = || R_v - R_r ||^2
///
/// as the difference of unit quaternions, with R_r sign-aligned to R_v's
/// hemisphere (q and -q are the same rotation). Unlike E_d it always pulls
/// the virtual camera towards the real one, which keeps the virtual camera
/// from drifting far enough to hit the frame boundary.
///
/// Parameters: R_v quaternion [4]. Residuals [4]: sqrt(w_o) (q_v - q_r).
class FollowingCost {
 public:
  FollowingCost(const Eigen::Quaterniond& R_r, double scale)
      : R_r_(R_r), scale_(scale) {}

  template <typename T>
  bool operator()(const T* q, T* residuals) const {
    const Eigen::Quaternion<T> R_v = QuaternionFromBlock(q);
    // Align the constant to the variable: R_r on R_v's hemisphere.
    const Eigen::Matrix<T, 4, 1> cv = R_v.coeffs();
    const T dot = cv(0) * R_r_.x() + cv(1) * R_r_.y() + cv(2) * R_r_.z() +
                  cv(3) * R_r_.w();
    const double sign = dot < T(0.0) ? -1.0 : 1.0;
    for (int i = 0; i < 4; ++i) {
      residuals[i] = T(scale_) * (cv(i) - T(sign * R_r_.coeffs()(i)));
    }
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Quaterniond& R_r,
                                     double scale) {
    return new ceres::AutoDiffCostFunction<FollowingCost, 4, 4>(
        new FollowingCost(R_r, scale));
  }

 private:
  const Eigen::Quaterniond R_r_;
  const double scale_;
};

}  // namespace steadiface

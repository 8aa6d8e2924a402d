#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "steadiface_core/stabilizer/quaternion_residuals.h"

namespace steadiface {

/// Horizon term E_h (ours; output/horizon level or lock): the virtual
/// camera's roll against gravity, outside a tolerance phi_0,
///
///   E_h(R_v) = w_h (|sin(phi)| - sin(phi_0))_+^2,
///   sin(phi) = u_x / |(u_x, u_y)|,  u = R_v u_w
///
/// with u_w the "up" (against gravity) in the gyro's world frame
/// (GravityEstimator) and u its image in the virtual camera: phi is the
/// angle about the optical axis between the image's up (-y) and gravity's.
/// phi_0 is level's tolerance (0 for lock): a roll within the gravity
/// estimate's own error is left alone. 0 (no pull) when the camera looks
/// straight up or down (|(u_x, u_y)| < 1e-3).
///
/// Parameters: R_v quaternion [4].
/// Residuals [1]: sqrt(w_h) (sin(phi) - sin(phi_0)) where sin(phi) >
/// sin(phi_0), sqrt(w_h) (sin(phi) + sin(phi_0)) where sin(phi) <
/// -sin(phi_0), else 0.
class HorizonCost {
 public:
  /// `scale` sqrt(w_h); `tolerance_sin` sin(phi_0), >= 0.
  HorizonCost(const Eigen::Vector3d& up_world, double scale, double tolerance_sin)
      : up_world_(up_world), scale_(scale), tolerance_sin_(tolerance_sin) {}

  template <typename T>
  bool operator()(const T* q, T* residual) const {
    const Eigen::Quaternion<T> R_v = QuaternionFromBlock(q);
    const Eigen::Matrix<T, 3, 1> u = R_v * up_world_.cast<T>();
    const T n2 = u(0) * u(0) + u(1) * u(1);
    if (n2 < T(1e-6)) {
      residual[0] = T(0.0);
      return true;
    }
    const T s = u(0) / sqrt(n2);
    const T d(tolerance_sin_);
    residual[0] = T(scale_) * (s > d ? s - d : (s < -d ? s + d : T(0.0)));
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& up_world,
                                     double scale, double tolerance_sin) {
    return new ceres::AutoDiffCostFunction<HorizonCost, 1, 4>(
        new HorizonCost(up_world, scale, tolerance_sin));
  }

 private:
  const Eigen::Vector3d up_world_;
  const double scale_;
  const double tolerance_sin_;
};

}  // namespace steadiface

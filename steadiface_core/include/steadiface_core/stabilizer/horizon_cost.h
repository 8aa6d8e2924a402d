#pragma once

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "steadiface_core/stabilizer/quaternion_residuals.h"

namespace steadiface {

/// Horizon term E_h (ours; output/horizon level or lock): the virtual
/// camera's roll against gravity,
///
///   E_h(R_v) = w_h sin^2(phi),  sin(phi) = u_x / |(u_x, u_y)|,  u = R_v u_w
///
/// with u_w the "up" (against gravity) in the gyro's world frame
/// (GravityEstimator) and u its image in the virtual camera: phi is the
/// angle about the optical axis between the image's up (-y) and gravity's.
/// 0 (no pull) when the camera looks straight up or down (|(u_x, u_y)| <
/// 1e-3).
///
/// Parameters: R_v quaternion [4].
/// Residuals [1]: sqrt(w_h) sin(phi).
class HorizonCost {
 public:
  HorizonCost(const Eigen::Vector3d& up_world, double scale)
      : up_world_(up_world), scale_(scale) {}

  template <typename T>
  bool operator()(const T* q, T* residual) const {
    const Eigen::Quaternion<T> R_v = QuaternionFromBlock(q);
    const Eigen::Matrix<T, 3, 1> u = R_v * up_world_.cast<T>();
    const T n2 = u(0) * u(0) + u(1) * u(1);
    if (n2 < T(1e-6)) {
      residual[0] = T(0.0);
      return true;
    }
    residual[0] = T(scale_) * u(0) / sqrt(n2);
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector3d& up_world,
                                     double scale) {
    return new ceres::AutoDiffCostFunction<HorizonCost, 1, 4>(
        new HorizonCost(up_world, scale));
  }

 private:
  const Eigen::Vector3d up_world_;
  const double scale_;
};

}  // namespace steadiface

#pragma once

#include <ceres/autodiff_cost_function.h>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/stabilizer/quaternion_residuals.h"

namespace steadiface {

/// Landmark fitting term E_f (paper §4.2, Eq. 6), one landmark:
///
///   E_f(P_v) = sum_i || proj(L_i, P_v, P_r) - H ||^2
///
/// with proj(L) = Π L = K_v R_v (K_r R_r)^-1 [L_x, L_y, 1]^T (Eq. 4). We add
/// one block per landmark, each scaled by sqrt(w_f / N) so the weight does
/// not depend on how many landmarks the model has (68 for dlib, 133 in the
/// paper). R_r is the real rotation of the landmark's own image row.
///
/// Parameters: R_v quaternion [4] (x, y, z, w), t [2].
/// Residuals [2]: scale * (proj(L) - H), normalized units.
class FittingCost {
 public:
  FittingCost(const Eigen::Vector2d& L, const Eigen::Quaterniond& R_r,
              const Eigen::Vector2d& H, double f_r, double f_v, double scale)
      : L_(L), R_r_(R_r), H_(H), f_r_(f_r), f_v_(f_v), scale_(scale) {}

  template <typename T>
  bool operator()(const T* q, const T* t, T* residuals) const {
    const Eigen::Quaternion<T> R_v = QuaternionFromBlock(q);
    const Eigen::Matrix<T, 2, 1> tt(t[0], t[1]);
    Eigen::Matrix<T, 2, 1> p;
    ProjectRealToVirtual<T>(R_v, tt, R_r_, f_r_, f_v_, L_, &p);
    residuals[0] = T(scale_) * (p(0) - T(H_.x()));
    residuals[1] = T(scale_) * (p(1) - T(H_.y()));
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector2d& L,
                                     const Eigen::Quaterniond& R_r,
                                     const Eigen::Vector2d& H, double f_r,
                                     double f_v, double scale) {
    return new ceres::AutoDiffCostFunction<FittingCost, 2, 4, 2>(
        new FittingCost(L, R_r, H, f_r, f_v, scale));
  }

 private:
  const Eigen::Vector2d L_;
  const Eigen::Quaterniond R_r_;
  const Eigen::Vector2d H_;
  const double f_r_, f_v_, scale_;
};

}  // namespace steadiface

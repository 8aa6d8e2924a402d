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
/// Extension (StabilizerOptions::intentional_window_s > 0): the C0 target
/// R_v,-1 is replaced by Δ_int R_v,-1, the previous virtual rotation moved
/// by the camera's intentional rotation over one frame (its mean rotation
/// rate over a trailing window). For a still hand Δ_int ~ I and the term
/// is the paper's; during a pan the paper's C0 term makes the virtual camera
/// lag by (w_r,C0 / w_o) times the per-frame pan angle, this one does not.
///
/// Parameters: R_v quaternion [4].
/// Residuals [8]: sqrt(w_r,C0) (q_v - q_v,-1) [4],
///                sqrt(w_r,C1) (q_v q_v,-1^-1 - q_v,-1 q_v,-2^-1) [4].
class RotationSmoothnessCost {
 public:
  RotationSmoothnessCost(const Eigen::Quaterniond& c0_target,
                         const Eigen::Quaterniond& prev,
                         const Eigen::Quaterniond& prev_delta, bool has_c1,
                         double scale_c0, double scale_c1)
      : c0_target_(c0_target),
        prev_(prev),
        prev_delta_(prev_delta),
        has_c1_(has_c1),
        scale_c0_(scale_c0),
        scale_c1_(scale_c1) {}

  template <typename T>
  bool operator()(const T* q, T* residuals) const {
    const Eigen::Quaternion<T> R_v = QuaternionFromBlock(q);
    const Eigen::Matrix<T, 4, 1> c0 = AlignedCoeffs<T>(R_v, c0_target_);
    for (int i = 0; i < 4; ++i) {
      residuals[i] = T(scale_c0_) * (c0(i) - T(c0_target_.coeffs()(i)));
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

  /// `c0_target` = R_v,-1 for the paper's term.
  static ceres::CostFunction* Create(const Eigen::Quaterniond& c0_target,
                                     const Eigen::Quaterniond& prev,
                                     const Eigen::Quaterniond& prev_delta,
                                     bool has_c1, double scale_c0,
                                     double scale_c1) {
    return new ceres::AutoDiffCostFunction<RotationSmoothnessCost, 8, 4>(
        new RotationSmoothnessCost(c0_target, prev, prev_delta, has_c1,
                                   scale_c0, scale_c1));
  }

 private:
  const Eigen::Quaterniond c0_target_, prev_, prev_delta_;
  const bool has_c1_;
  const double scale_c0_, scale_c1_;
};

}  // namespace steadiface

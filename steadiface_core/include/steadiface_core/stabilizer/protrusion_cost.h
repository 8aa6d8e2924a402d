#pragma once

#include <vector>

#include <ceres/dynamic_autodiff_cost_function.h>

#include "steadiface_core/stabilizer/quaternion_residuals.h"
#include "steadiface_core/warp/protrusion.h"

namespace steadiface {

/// Protrusion term E_p (paper §4.2, Eq. 11):
///
///   E_p(P_v) = || protrude(P_v, P_r) / α ||^2
///
/// protrude() is how far the output crop window, mapped into the real frame,
/// lands outside the real image boundary shrunk by `shrink_px` (the paper
/// shrinks it "to make it more sensitive"). α is the tolerated protrusion
/// [normalized units]. Rolling-shutter aware: every boundary sample uses the
/// real rotation of the input row it lands on (rows fixed from a check at the
/// initial pose). The geometry is ProtrusionGeometry's, the one shared with
/// the binary search and the warp.
///
/// Parameters: R_v quaternion [4], t [2].
/// Residuals [2 * samples]: sqrt(w_p) outside_px / (W α) per axis.
class ProtrusionCost {
 public:
  ProtrusionCost(const ProtrusionGeometry* geometry,
                 std::vector<Eigen::Quaterniond> R_r_per_sample,
                 double shrink_px, double scale)
      : geometry_(geometry),
        R_r_(std::move(R_r_per_sample)),
        shrink_px_(shrink_px),
        scale_(scale) {}

  template <typename T>
  bool operator()(T const* const* params, T* residuals) const {
    const Eigen::Quaternion<T> R_v = QuaternionFromBlock(params[0]);
    const Eigen::Matrix<T, 2, 1> t(params[1][0], params[1][1]);
    geometry_->Residuals<T>(R_v, t, R_r_, shrink_px_, scale_, residuals);
    return true;
  }

  /// `alpha` [normalized units]; `weight` = w_p. `geometry` must outlive the
  /// cost function.
  static ceres::CostFunction* Create(
      const ProtrusionGeometry* geometry,
      std::vector<Eigen::Quaterniond> R_r_per_sample, double shrink_px,
      double alpha, double weight) {
    const double scale =
        std::sqrt(weight) / (alpha * geometry->model().intrinsics().width);
    const int n = static_cast<int>(geometry->num_samples());
    auto* f = new ceres::DynamicAutoDiffCostFunction<ProtrusionCost, 4>(
        new ProtrusionCost(geometry, std::move(R_r_per_sample), shrink_px,
                           scale));
    f->AddParameterBlock(4);
    f->AddParameterBlock(2);
    f->SetNumResiduals(2 * n);
    return f;
  }

 private:
  const ProtrusionGeometry* geometry_;
  const std::vector<Eigen::Quaterniond> R_r_;
  const double shrink_px_, scale_;
};

}  // namespace steadiface

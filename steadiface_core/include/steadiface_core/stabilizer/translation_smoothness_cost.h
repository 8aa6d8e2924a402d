#pragma once

#include <ceres/autodiff_cost_function.h>
#include <Eigen/Core>

namespace steadiface {

/// Translation smoothness term E_t (paper §4.2, Eq. 10), C0 and C1:
///
///   E_t(t) = w_t,C0 || t - t_-1 ||^2 + w_t,C1 || 2 t_-1 - (t + t_-2) ||^2
///
/// Without a frame before the previous one, the C1 residuals are 0.
///
/// Parameters: t [2]. Residuals [4]: sqrt(w_t,C0)(t - t_-1) [2],
/// sqrt(w_t,C1)(2 t_-1 - t - t_-2) [2], normalized units.
class TranslationSmoothnessCost {
 public:
  TranslationSmoothnessCost(const Eigen::Vector2d& prev,
                            const Eigen::Vector2d& prev_prev, bool has_c1,
                            double scale_c0, double scale_c1)
      : prev_(prev),
        prev_prev_(prev_prev),
        has_c1_(has_c1),
        scale_c0_(scale_c0),
        scale_c1_(scale_c1) {}

  template <typename T>
  bool operator()(const T* t, T* residuals) const {
    for (int i = 0; i < 2; ++i) {
      residuals[i] = T(scale_c0_) * (t[i] - T(prev_(i)));
      residuals[2 + i] =
          has_c1_ ? T(scale_c1_) * (T(2.0 * prev_(i) - prev_prev_(i)) - t[i])
                  : T(0.0);
    }
    return true;
  }

  static ceres::CostFunction* Create(const Eigen::Vector2d& prev,
                                     const Eigen::Vector2d& prev_prev,
                                     bool has_c1, double scale_c0,
                                     double scale_c1) {
    return new ceres::AutoDiffCostFunction<TranslationSmoothnessCost, 4, 2>(
        new TranslationSmoothnessCost(prev, prev_prev, has_c1, scale_c0,
                                      scale_c1));
  }

 private:
  const Eigen::Vector2d prev_, prev_prev_;
  const bool has_c1_;
  const double scale_c0_, scale_c1_;
};

}  // namespace steadiface

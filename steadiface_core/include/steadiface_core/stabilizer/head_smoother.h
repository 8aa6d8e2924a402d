#pragma once

#include <Eigen/Core>

#include "steadiface_core/common/status.h"

namespace steadiface {

/// Options of the head trajectory smoother (paper Eq. 1). Defaults are the
/// paper's.
struct HeadSmootherOptions {
  /// w1: weight of staying where the target was on the previous frame [-].
  double w_stay = 5000.0;
  /// w2: weight of following the landmark centre [-].
  double w_follow = 1.0;
  /// d_ref: tolerated deviation of the target from the landmark centre
  /// [normalized units, fraction of the image width].
  double d_ref = 0.03;
};

Status ValidateHeadSmootherOptions(const HeadSmootherOptions& options);

/// Smooth target head centre H (paper §3.2, Eq. 1):
///
///   H = argmin_H  w1 ||H - H_prev||^2
///                + w2 ( max(|H - C|_x, |H - C|_y) / d_ref )^2
///   s.t. |H - C|_x < r_x and |H - C|_y < r_y
///
/// with C the landmark centre and r the crop margin per axis.
///
/// Solved exactly. Write D = H - C and a = H_prev - C. For a fixed
/// m = ||D||_inf the first term is separable, so its minimizer is the clamp
/// of a to [-b_i, b_i] with b_i = min(m, r_i); the objective then is a
/// one-dimensional, piecewise quadratic function of m with breakpoints at
/// |a_i| and r_i. Evaluating its minimum on every piece (stationary point
/// clamped to the piece) and taking the best is exact. The strict
/// constraint is enforced as |D_i| <= r_i (1 - 1e-9).
class HeadSmoother {
 public:
  explicit HeadSmoother(const HeadSmootherOptions& options)
      : options_(options) {}

  /// One step of Eq. 1. `margin` is r per axis (> 0); +infinity drops the
  /// constraint on that axis (the stabilizer does so when C is in the
  /// virtual view, where the box is not the reachable set).
  Eigen::Vector2d Solve(const Eigen::Vector2d& previous_target,
                        const Eigen::Vector2d& landmark_centre,
                        const Eigen::Vector2d& margin) const;

  /// The objective of Eq. 1 (for tests and diagnostics).
  double Objective(const Eigen::Vector2d& H, const Eigen::Vector2d& previous,
                   const Eigen::Vector2d& centre) const;

  const HeadSmootherOptions& options() const { return options_; }

 private:
  HeadSmootherOptions options_;
};

}  // namespace steadiface

#pragma once

#include <Eigen/Core>

namespace steadiface {

/// A causal low-pass of a 2D signal that follows ramps without lag: a
/// critically damped type-2 tracking loop at natural frequency `hz` (its
/// error on a constant-velocity input decays to 0, so a pan or a steady
/// walk passes), followed by a first-order low-pass at 5x `hz` (the loop
/// alone passes about 2 hz / f of motion at a faster frequency f, through
/// its zero). The loop's step is capped at 0.5 / (2 pi hz) so it stays
/// stable over long gaps.
class TrackingLowpass {
 public:
  /// `hz` > 0 [Hz].
  explicit TrackingLowpass(double hz = 1.0) : hz_(hz) {}

  /// Feeds `x`, `dt` [s] after the last sample, and returns the output. The
  /// first sample after construction or reset(), or one with dt <= 0 (or
  /// NaN), restarts the filter at `x`.
  const Eigen::Vector2d& Update(const Eigen::Vector2d& x, double dt);

  const Eigen::Vector2d& value() const { return smooth_; }
  bool started() const { return started_; }
  void reset() { started_ = false; }

 private:
  double hz_;
  bool started_ = false;
  Eigen::Vector2d slow_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d rate_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d smooth_ = Eigen::Vector2d::Zero();
};

}  // namespace steadiface

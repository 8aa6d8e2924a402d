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
  /// first sample after construction or Reset(), or one with dt <= 0 (or
  /// NaN), restarts the filter at `x`.
  const Eigen::Vector2d& Update(const Eigen::Vector2d& x, double dt);

  const Eigen::Vector2d& value() const { return smooth_; }
  bool started() const { return started_; }
  void Reset() { started_ = false; }

 private:
  double hz_;
  bool started_ = false;
  Eigen::Vector2d slow_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d rate_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d smooth_ = Eigen::Vector2d::Zero();
};

}  // namespace steadiface

namespace steadiface {

/// The slow part of a 2D position, such as a head's drift or a subject
/// walking across the view, without lag on ramps and without a slow start:
/// a constant-velocity Kalman filter (per axis; white acceleration noise of
/// density (2 pi hz)^4 against unit measurement noise density, so its
/// steady state is a type-2 tracking loop at natural frequency `hz`, damping
/// 0.71), started with an unknown velocity so a ramp is picked up within a
/// few samples instead of after the loop's settling time (several 1 / hz);
/// then a first-order low-pass at 5x `hz`, fed the position moved ahead by
/// the velocity times its time constant, so a ramp passes it without lag
/// too, while it attenuates what the loop passes of faster motion (about
/// 2 hz / f at a frequency f).
class SlowMotionFilter {
 public:
  /// `hz` > 0 [Hz].
  explicit SlowMotionFilter(double hz = 1.0) : hz_(hz) {}

  /// Feeds `x`, `dt` [s] after the last sample, and returns the slow part.
  /// The first sample after construction or Reset(), or one with dt <= 0
  /// (or NaN), restarts the filter at `x` with an unknown velocity.
  const Eigen::Vector2d& Update(const Eigen::Vector2d& x, double dt);

  const Eigen::Vector2d& value() const { return smooth_; }
  const Eigen::Vector2d& velocity() const { return velocity_; }
  bool started() const { return started_; }
  void Reset() { started_ = false; }

 private:
  double hz_;
  bool started_ = false;
  bool has_covariance_ = false;     // P is set from the first step's dt
  Eigen::Matrix2d P_ = Eigen::Matrix2d::Zero();  // (position, velocity)
  Eigen::Vector2d position_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d velocity_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d smooth_ = Eigen::Vector2d::Zero();
};

}  // namespace steadiface

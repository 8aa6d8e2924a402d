#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace steadiface {

/// The camera's path without its shake, for sizing the dynamic crop: the
/// real rotation through a causal, critically damped second-order low-pass
/// on SO(3) with natural frequency 2 pi `hz`. Being second order, it follows
/// a steady pan without lag, so what separates it from the real camera is
/// the shake a gyro-only virtual camera removes. The margin that separation
/// needs is what the crop must hold however the face term then uses the
/// rest (global mode may spend more margin holding a drifting face; the
/// crop does not grow for that).
class ShakePath {
 public:
  explicit ShakePath(double hz) : k_(2.0 * 3.14159265358979 * hz) {}

  /// Advances to the real rotation `R_r` (the frame's middle row), `dt` [s]
  /// after the previous frame; the first call (or dt <= 0 after reset())
  /// starts the path there. Returns the path's rotation now.
  const Eigen::Quaterniond& Update(const Eigen::Quaterniond& R_r, double dt);
  void Reset() { started_ = false; }

 private:
  const double k_;  // natural frequency [rad/s]
  bool started_ = false;
  Eigen::Quaterniond R_ = Eigen::Quaterniond::Identity();
  Eigen::Quaterniond R_prev_ = Eigen::Quaterniond::Identity();  // the last R_r
  Eigen::Vector3d omega_ =
      Eigen::Vector3d::Zero();  // in the path's frame [rad/s]
};

}  // namespace steadiface

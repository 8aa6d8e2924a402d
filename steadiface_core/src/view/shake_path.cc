#include "steadiface_core/view/shake_path.h"

#include <algorithm>
#include <cmath>

#include "steadiface_core/common/so3.h"

namespace steadiface {

const Eigen::Quaterniond& ShakePath::Update(const Eigen::Quaterniond& R_r,
                                            double dt) {
  if (!R_r.coeffs().allFinite()) return R_;
  const Eigen::Quaterniond R_r_n = R_r.normalized();
  if (!started_ || !(dt > 0.0)) {
    if (!started_) {
      R_ = R_prev_ = R_r_n;
      omega_.setZero();
      started_ = true;
    }
    return R_;
  }
  dt = std::min(dt, 0.2);  // a gap: no wild step
  // The path moves on to now at its rate; then its rate takes in the error
  // and the rate error as the path sees them (e'' = -k^2 e - 2 k e',
  // critically damped; the damping acts on the rate error, so a steady pan
  // is followed without lag).
  const Eigen::Quaterniond I = Eigen::Quaterniond::Identity();
  R_ = (R_ * ExpSO3(omega_ * dt)).normalized();
  const Eigen::Vector3d e = LogSO3(AlignSign(R_.conjugate() * R_r_n, I));
  const Eigen::Vector3d omega_r =
      LogSO3(AlignSign(R_prev_.conjugate() * R_r_n, I)) / dt;
  R_prev_ = R_r_n;
  omega_ += (k_ * k_ * e + 2.0 * k_ * (omega_r - omega_)) * dt;
  return R_;
}

}  // namespace steadiface

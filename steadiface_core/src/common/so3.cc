#include "steadiface_core/common/so3.h"

#include <algorithm>
#include <cmath>

namespace steadiface {

Eigen::Quaterniond ExpSO3(const Eigen::Vector3d& phi) {
  const double theta2 = phi.squaredNorm();
  const double theta = std::sqrt(theta2);
  double w, s;  // q = (cos(theta/2), sin(theta/2)/theta * phi)
  if (theta < 1e-5) {
    w = 1.0 - theta2 / 8.0;
    s = 0.5 - theta2 / 48.0;
  } else {
    w = std::cos(0.5 * theta);
    s = std::sin(0.5 * theta) / theta;
  }
  return Eigen::Quaterniond(w, s * phi.x(), s * phi.y(), s * phi.z());
}

Eigen::Vector3d LogSO3(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const double n = q.vec().norm();
  if (n < 1e-8) {
    // theta ~ 2n, phi ~ 2 vec / w.
    return 2.0 * q.vec() / q.w();
  }
  const double theta = 2.0 * std::atan2(n, q.w());
  return q.vec() * (theta / n);
}

double AngleBetween(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return LogSO3(a.conjugate() * b).norm();
}

Eigen::Quaterniond AlignSign(const Eigen::Quaterniond& q,
                             const Eigen::Quaterniond& reference) {
  if (q.coeffs().dot(reference.coeffs()) < 0.0) {
    return Eigen::Quaterniond(-q.coeffs());
  }
  return q;
}

}  // namespace steadiface

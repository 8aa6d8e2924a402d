#pragma once

#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace steadiface {

/// Maps a Ceres parameter block stored in Eigen's coefficient order
/// (x, y, z, w), as EigenQuaternionManifold expects.
template <typename T>
Eigen::Quaternion<T> QuaternionFromBlock(const T* q) {
  return Eigen::Quaternion<T>(q[3], q[0], q[1], q[2]);
}

/// Rotation vector (axis * angle) of a unit quaternion, generic for Jets and
/// smooth at the identity (first-order series there, where atan2 of a zero
/// vector would give an undefined derivative).
template <typename T>
Eigen::Matrix<T, 3, 1> RotationVector(const Eigen::Quaternion<T>& q_in) {
  using std::atan2;
  using std::sqrt;
  Eigen::Quaternion<T> q = q_in;
  if (q.w() < T(0.0)) q.coeffs() = -q.coeffs();
  const T n2 = q.vec().squaredNorm();
  if (n2 > T(1e-16)) {
    const T n = sqrt(n2);
    return q.vec() * (T(2.0) * atan2(n, q.w()) / n);
  }
  // 2 atan(n / w) / n ~= (2 / w) (1 - n^2 / (3 w^2)).
  return q.vec() * (T(2.0) / q.w() * (T(1.0) - n2 / (T(3.0) * q.w() * q.w())));
}

/// Coefficients of `q` on the hemisphere of `reference` (double reference):
/// the paper's "sign-aligned" quaternion for differences.
template <typename T>
Eigen::Matrix<T, 4, 1> AlignedCoeffs(const Eigen::Quaternion<T>& q,
                                     const Eigen::Quaterniond& reference) {
  const Eigen::Matrix<T, 4, 1> c = q.coeffs();
  const T dot = c(0) * reference.x() + c(1) * reference.y() +
                c(2) * reference.z() + c(3) * reference.w();
  return dot < T(0.0) ? Eigen::Matrix<T, 4, 1>(-c) : c;
}

}  // namespace steadiface

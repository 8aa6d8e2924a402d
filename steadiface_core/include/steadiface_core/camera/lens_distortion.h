#pragma once

#include <cmath>

#include <Eigen/Core>

#include "steadiface_core/camera/camera_intrinsics.h"

namespace steadiface {

/// Applies the lens distortion of `k` to an ideal (undistorted) point in
/// camera coordinates m = (X/Z, Y/Z), returning distorted camera coordinates
/// (multiply by fx, fy and add cx, cy for the raw pixel). Same formulas as
/// OpenCV's projectPoints (plumb_bob/rational) and fisheye::projectPoints
/// (equidistant). Generic for Ceres autodiff. kNone is the identity.
template <typename T>
Eigen::Matrix<T, 2, 1> DistortCameraPoint(const CameraIntrinsics& k,
                                          const Eigen::Matrix<T, 2, 1>& m) {
  using std::atan;
  using std::sqrt;
  const auto& d = k.distortion_coeffs;
  auto coeff = [&d](size_t i) { return i < d.size() ? d[i] : 0.0; };
  const T x = m(0), y = m(1);
  if (k.distortion == DistortionModel::kPlumbBob) {
    const T r2 = x * x + y * y;
    const T r4 = r2 * r2, r6 = r4 * r2;
    const double k1 = coeff(0), k2 = coeff(1), p1 = coeff(2), p2 = coeff(3),
                 k3 = coeff(4), k4 = coeff(5), k5 = coeff(6), k6 = coeff(7);
    const T radial = (T(1.0) + k1 * r2 + k2 * r4 + k3 * r6) /
                     (T(1.0) + k4 * r2 + k5 * r4 + k6 * r6);
    Eigen::Matrix<T, 2, 1> out;
    out(0) = x * radial + T(2.0 * p1) * x * y + p2 * (r2 + T(2.0) * x * x);
    out(1) = y * radial + p1 * (r2 + T(2.0) * y * y) + T(2.0 * p2) * x * y;
    return out;
  }
  if (k.distortion == DistortionModel::kEquidistant) {
    const T r2 = x * x + y * y;
    if (!(r2 > T(1e-24))) return m;
    const T r = sqrt(r2);
    const T theta = atan(r);
    const T t2 = theta * theta;
    const T t4 = t2 * t2, t6 = t4 * t2, t8 = t4 * t4;
    const T theta_d = theta * (T(1.0) + coeff(0) * t2 + coeff(1) * t4 +
                               coeff(2) * t6 + coeff(3) * t8);
    const T scale = theta_d / r;
    return Eigen::Matrix<T, 2, 1>(x * scale, y * scale);
  }
  return m;
}

/// Inverse of DistortCameraPoint by fixed-point/Newton iteration (double
/// only). Returns false if it did not converge to 1e-10 within 30 steps.
bool UndistortCameraPoint(const CameraIntrinsics& k,
                          const Eigen::Vector2d& distorted,
                          Eigen::Vector2d* undistorted);

/// Raw (distorted) pixel -> ideal (undistorted) pixel of the same
/// intrinsics. Identity without distortion.
bool UndistortPixel(const CameraIntrinsics& k, const Eigen::Vector2d& raw,
                    Eigen::Vector2d* ideal);

}  // namespace steadiface

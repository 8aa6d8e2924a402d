#include "steadiface_core/camera/lens_distortion.h"

#include <Eigen/LU>

namespace steadiface {

bool UndistortCameraPoint(const CameraIntrinsics& k,
                          const Eigen::Vector2d& distorted,
                          Eigen::Vector2d* undistorted) {
  if (!k.HasDistortion()) {
    *undistorted = distorted;
    return true;
  }
  // Newton's method with a numeric Jacobian; the distortion is smooth and
  // close to identity over the valid image.
  Eigen::Vector2d m = distorted;
  for (int it = 0; it < 30; ++it) {
    const Eigen::Vector2d f = DistortCameraPoint<double>(k, m) - distorted;
    if (f.norm() < 1e-10) {
      *undistorted = m;
      return true;
    }
    const double h = 1e-7;
    Eigen::Matrix2d J;
    J.col(0) = (DistortCameraPoint<double>(k, m + Eigen::Vector2d(h, 0)) -
                DistortCameraPoint<double>(k, m - Eigen::Vector2d(h, 0))) /
               (2 * h);
    J.col(1) = (DistortCameraPoint<double>(k, m + Eigen::Vector2d(0, h)) -
                DistortCameraPoint<double>(k, m - Eigen::Vector2d(0, h))) /
               (2 * h);
    if (std::abs(J.determinant()) < 1e-12) return false;
    m -= J.inverse() * f;
    if (!m.allFinite()) return false;
  }
  const bool ok = (DistortCameraPoint<double>(k, m) - distorted).norm() < 1e-8;
  if (ok) *undistorted = m;
  return ok;
}

bool UndistortPixel(const CameraIntrinsics& k, const Eigen::Vector2d& raw,
                    Eigen::Vector2d* ideal) {
  if (!k.HasDistortion()) {
    *ideal = raw;
    return true;
  }
  const Eigen::Vector2d d((raw.x() - k.cx) / k.fx, (raw.y() - k.cy) / k.fy);
  Eigen::Vector2d m;
  if (!UndistortCameraPoint(k, d, &m)) return false;
  *ideal = Eigen::Vector2d(m.x() * k.fx + k.cx, m.y() * k.fy + k.cy);
  return true;
}

}  // namespace steadiface

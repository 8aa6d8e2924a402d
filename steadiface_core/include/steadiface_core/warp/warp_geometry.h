#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/camera/lens_distortion.h"
#include "steadiface_core/gyro/row_rotations.h"

namespace steadiface {

/// The inverse of Π, down to raw input pixels: a virtual normalized point V
/// -> the raw (distorted) pixel of the real frame it comes from, for a real
/// rotation R_r (world -> camera) of that pixel's row. Generic for Ceres.
/// Returns false when the ray lies behind the real camera (*pixel is then
/// written but meaningless).
template <typename T>
bool VirtualToRealPixel(const CameraModel& model,
                        const Eigen::Quaternion<T>& R_v,
                        const Eigen::Matrix<T, 2, 1>& t,
                        const Eigen::Quaterniond& R_r, const Eigen::Vector2d& V,
                        Eigen::Matrix<T, 2, 1>* pixel) {
  const double f_v = model.virtual_focal();
  Eigen::Matrix<T, 3, 1> ray_v;
  ray_v(0) = (T(V.x() - 0.5) - t(0)) / f_v;
  ray_v(1) = (T(V.y() - 0.5) - t(1)) / f_v;
  ray_v(2) = T(1.0);
  const Eigen::Matrix<T, 3, 1> ray_w = R_v.conjugate() * ray_v;
  const Eigen::Matrix<T, 3, 1> ray_r = R_r.cast<T>() * ray_w;
  const bool in_front = ray_r(2) > T(1e-9);
  const T z = in_front ? ray_r(2) : T(1e-9);
  Eigen::Matrix<T, 2, 1> m(ray_r(0) / z, ray_r(1) / z);
  const CameraIntrinsics& k = model.intrinsics();
  if (k.HasDistortion()) m = DistortCameraPoint<T>(k, m);
  (*pixel)(0) = T(k.fx) * m(0) + T(k.cx);
  (*pixel)(1) = T(k.fy) * m(1) + T(k.cy);
  return in_front;
}

/// Rolling-shutter-aware version: the real rotation depends on the input row
/// the point lands on, which depends on the rotation. Solved as the fixed
/// point y = row(VirtualToRealPixel(V, R_r(y))), starting from `*row` (pass
/// the middle row or a neighbour's solution).
///
/// Convergence: one iteration changes the row error by the factor
/// k ~= readout/(H-1) * |dy/dt| where dy/dt is the image-row velocity the
/// rotation induces (~ fy * |omega_x|). For a 30 ms readout, 720 rows,
/// fy = 1000 px and a fast 3 rad/s shake, k ~= 0.13, so each iteration gains
/// about one digit; 4 iterations reach < 0.01 px. The loop stops once the
/// row moves by less than `tolerance_px`. The row is clamped to [0, H-1]
/// (points outside the frame take the nearest row's rotation).
/// Returns false when the ray is behind the camera or the iteration produced
/// a non-finite value.
inline bool VirtualToRealPixelRS(const CameraModel& model,
                                 const Eigen::Quaterniond& R_v,
                                 const Eigen::Vector2d& t,
                                 const RowRotations& rows,
                                 const Eigen::Vector2d& V, int max_iterations,
                                 double tolerance_px, Eigen::Vector2d* pixel,
                                 double* row) {
  const double h1 = rows.height() - 1;
  double y = std::min(std::max(*row, 0.0), h1);
  Eigen::Vector2d p;
  const int iterations = rows.samples() > 1 ? std::max(1, max_iterations) : 1;
  for (int it = 0; it < iterations; ++it) {
    if (!VirtualToRealPixel<double>(model, R_v, t, rows.At(y), V, &p)) {
      return false;
    }
    if (!p.allFinite()) return false;
    const double y_new = std::min(std::max(p.y(), 0.0), h1);
    const bool done = std::abs(y_new - y) < tolerance_px;
    y = y_new;
    if (done) break;
  }
  *pixel = p;
  *row = y;
  return true;
}

}  // namespace steadiface

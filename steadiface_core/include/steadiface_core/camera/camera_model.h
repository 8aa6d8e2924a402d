#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/common/status.h"

namespace steadiface {

// Paper §4.1 (Representation).
//
// Normalized image coordinates. The paper writes the real intrinsics as
// K_r = [f_r 0 0.5; 0 f_r 0.5; 0 0 1], i.e. the image lives around (0.5, 0.5)
// with the principal point exactly there. For a W x H image with calibrated
// (fx, fy, cx, cy) we define, isotropically (one scale for both axes, so
// angles and rotations stay undistorted for non-square images):
//
//   n_x = (x - cx) / W + 0.5
//   n_y = (y - cy) * (fx / fy) / W + 0.5
//   f_r = fx / W
//
// So x spans about [0, 1] and y spans about 0.5 +- H / (2 W); a ray
// (X, Y, Z) in the camera frame lands at n = (f_r X/Z + 0.5, f_r Y/Z + 0.5).
// The fx/fy factor folds non-square pixels into the same f_r. Lengths in
// normalized units (d_ref, crop margins, alpha) are fractions of the width.
//
// Rotations. R_r and R_v map world directions into the camera frame
// (R = R_camera<-world), which is the reading of the paper's
// Π = K_v R_v (K_r R_r)^-1: K_r^-1 lifts a real pixel to a ray in the real
// camera, R_r^-1 takes it to the world, R_v into the virtual camera, K_v
// projects it. Camera axes follow ROS optical frames: x right, y down, z
// forward.
//
// Virtual intrinsics: K_v = [f_v 0 0.5 + t_x; 0 f_v 0.5 + t_y; 0 0 1] with
// f_v = virtual_focal_scale * f_r, fixed, and t the 2D principal offset.

/// Options of the camera model.
struct CameraModelOptions {
  /// Virtual focal length as a multiple of the real one, f_v / f_r [-].
  /// 1.0 keeps the scale of the input; >1 zooms in.
  double virtual_focal_scale = 1.0;
};

Status ValidateCameraModelOptions(const CameraModelOptions& options);

/// The real camera K_r and the virtual camera K_v of the paper, and the
/// mapping between pixels and normalized coordinates.
class CameraModel {
 public:
  /// Validates `intrinsics` and `options`; on error `*model` is untouched.
  static Status Create(const CameraIntrinsics& intrinsics,
                       const CameraModelOptions& options, CameraModel* model);

  CameraModel() = default;

  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  /// f_r [normalized units].
  double real_focal() const { return f_r_; }
  /// f_v [normalized units].
  double virtual_focal() const { return f_v_; }

  /// Real (distortion-free) pixel -> normalized coordinates.
  Eigen::Vector2d PixelToNormalized(const Eigen::Vector2d& pixel) const;
  /// Raw pixel as the camera recorded it -> normalized coordinates: the lens
  /// distortion removed (UndistortPixel), then PixelToNormalized. Returns
  /// false where the undistortion does not converge; `*normalized` is then
  /// the raw pixel's.
  bool RawPixelToNormalized(const Eigen::Vector2d& raw, Eigen::Vector2d* normalized) const;
  /// Normalized coordinates -> real pixel.
  Eigen::Vector2d NormalizedToPixel(const Eigen::Vector2d& normalized) const;

  /// K_r.
  Eigen::Matrix3d RealK() const;
  /// K_v for principal offset t.
  Eigen::Matrix3d VirtualK(const Eigen::Vector2d& t) const;

  /// Π(P_v, P_r) = K_v R_v (K_r R_r)^-1 (paper Eq. 3): real normalized ->
  /// virtual normalized (homogeneous).
  Eigen::Matrix3d Homography(const Eigen::Quaterniond& R_v,
                             const Eigen::Vector2d& t,
                             const Eigen::Quaterniond& R_r) const;

  /// proj(L, P_v, P_r) (paper Eq. 4). Returns false when L's ray lies behind
  /// the virtual camera (then *out is not written).
  bool Project(const Eigen::Vector2d& L, const Eigen::Quaterniond& R_v,
               const Eigen::Vector2d& t, const Eigen::Quaterniond& R_r,
               Eigen::Vector2d* out) const;

  /// The inverse of proj: a virtual normalized point -> the real normalized
  /// point it comes from. Returns false when the ray lies behind the real
  /// camera.
  bool Unproject(const Eigen::Vector2d& V, const Eigen::Quaterniond& R_v,
                 const Eigen::Vector2d& t, const Eigen::Quaterniond& R_r,
                 Eigen::Vector2d* out) const;

 private:
  CameraIntrinsics intrinsics_;
  double f_r_ = 1.0;
  double f_v_ = 1.0;
  double y_scale_ = 1.0;  // fx / fy
};

/// proj(L) written generically for Ceres autodiff: the real normalized point L
/// through R_r^-1, then R_v and K_v(t). `R_v` is world->virtual camera,
/// `R_r` world->real camera. Returns false when the point is behind the
/// virtual camera (depth <= 1e-9); *out is then still written but unusable.
template <typename T>
bool ProjectRealToVirtual(const Eigen::Quaternion<T>& R_v,
                          const Eigen::Matrix<T, 2, 1>& t,
                          const Eigen::Quaterniond& R_r, double f_r, double f_v,
                          const Eigen::Vector2d& L,
                          Eigen::Matrix<T, 2, 1>* out) {
  const Eigen::Vector3d ray_real((L.x() - 0.5) / f_r, (L.y() - 0.5) / f_r, 1.0);
  const Eigen::Vector3d ray_world = R_r.conjugate() * ray_real;
  const Eigen::Matrix<T, 3, 1> ray_virtual = R_v * ray_world.cast<T>();
  const T z = ray_virtual.z();
  const bool in_front = z > T(1e-9);
  const T safe_z = in_front ? z : T(1e-9);
  (*out)(0) = T(f_v) * ray_virtual.x() / safe_z + T(0.5) + t(0);
  (*out)(1) = T(f_v) * ray_virtual.y() / safe_z + T(0.5) + t(1);
  return in_front;
}

}  // namespace steadiface

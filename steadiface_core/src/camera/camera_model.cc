#include "steadiface_core/camera/camera_model.h"

#include <cmath>
#include <sstream>

#include "steadiface_core/camera/lens_distortion.h"

namespace steadiface {

Status ValidateCameraModelOptions(const CameraModelOptions& options) {
  if (!std::isfinite(options.virtual_focal_scale) ||
      options.virtual_focal_scale < 0.25 || options.virtual_focal_scale > 4.0) {
    std::ostringstream err;
    err << "camera.virtual_focal_scale must be in [0.25, 4], got "
        << options.virtual_focal_scale;
    return Status::Error(err.str());
  }
  return Status::Ok();
}

Status CameraModel::Create(const CameraIntrinsics& intrinsics,
                           const CameraModelOptions& options,
                           CameraModel* model) {
  Status s = ValidateIntrinsics(intrinsics);
  if (!s.ok()) return s;
  s = ValidateCameraModelOptions(options);
  if (!s.ok()) return s;
  model->intrinsics_ = intrinsics;
  model->f_r_ = intrinsics.fx / intrinsics.width;
  model->f_v_ = options.virtual_focal_scale * model->f_r_;
  model->y_scale_ = intrinsics.fx / intrinsics.fy;
  return Status::Ok();
}

Eigen::Vector2d CameraModel::PixelToNormalized(
    const Eigen::Vector2d& pixel) const {
  const double w = intrinsics_.width;
  return Eigen::Vector2d((pixel.x() - intrinsics_.cx) / w + 0.5,
                         (pixel.y() - intrinsics_.cy) * y_scale_ / w + 0.5);
}

bool CameraModel::RawPixelToNormalized(const Eigen::Vector2d& raw,
                                       Eigen::Vector2d* normalized) const {
  Eigen::Vector2d ideal = raw;
  const bool ok = UndistortPixel(intrinsics_, raw, &ideal);
  *normalized = PixelToNormalized(ideal);
  return ok;
}

Eigen::Vector2d CameraModel::NormalizedToPixel(
    const Eigen::Vector2d& normalized) const {
  const double w = intrinsics_.width;
  return Eigen::Vector2d((normalized.x() - 0.5) * w + intrinsics_.cx,
                         (normalized.y() - 0.5) * w / y_scale_ + intrinsics_.cy);
}

Eigen::Matrix3d CameraModel::RealK() const {
  Eigen::Matrix3d k;
  k << f_r_, 0.0, 0.5, 0.0, f_r_, 0.5, 0.0, 0.0, 1.0;
  return k;
}

Eigen::Matrix3d CameraModel::VirtualK(const Eigen::Vector2d& t) const {
  Eigen::Matrix3d k;
  k << f_v_, 0.0, 0.5 + t.x(), 0.0, f_v_, 0.5 + t.y(), 0.0, 0.0, 1.0;
  return k;
}

Eigen::Matrix3d CameraModel::Homography(const Eigen::Quaterniond& R_v,
                                        const Eigen::Vector2d& t,
                                        const Eigen::Quaterniond& R_r) const {
  // K_v R_v (K_r R_r)^-1 = K_v R_v R_r^T K_r^-1.
  return VirtualK(t) * (R_v * R_r.conjugate()).toRotationMatrix() *
         RealK().inverse();
}

bool CameraModel::Project(const Eigen::Vector2d& L,
                          const Eigen::Quaterniond& R_v,
                          const Eigen::Vector2d& t,
                          const Eigen::Quaterniond& R_r,
                          Eigen::Vector2d* out) const {
  Eigen::Vector2d v;
  if (!ProjectRealToVirtual<double>(R_v, t, R_r, f_r_, f_v_, L, &v)) {
    return false;
  }
  *out = v;
  return true;
}

bool CameraModel::Unproject(const Eigen::Vector2d& V,
                            const Eigen::Quaterniond& R_v,
                            const Eigen::Vector2d& t,
                            const Eigen::Quaterniond& R_r,
                            Eigen::Vector2d* out) const {
  const Eigen::Vector3d ray_virtual((V.x() - 0.5 - t.x()) / f_v_,
                                    (V.y() - 0.5 - t.y()) / f_v_, 1.0);
  const Eigen::Vector3d ray_real = R_r * (R_v.conjugate() * ray_virtual);
  if (ray_real.z() <= 1e-9) return false;
  *out = Eigen::Vector2d(f_r_ * ray_real.x() / ray_real.z() + 0.5,
                         f_r_ * ray_real.y() / ray_real.z() + 0.5);
  return true;
}

}  // namespace steadiface

#include "steadiface_core/camera/output_geometry.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace steadiface {

Status ValidateOutputOptions(const OutputOptions& o) {
  std::ostringstream err;
  if (!std::isfinite(o.crop_ratio) || o.crop_ratio < 0.0 ||
      o.crop_ratio > 0.4) {
    err << "output.crop_ratio must be in [0, 0.4], got " << o.crop_ratio;
  } else if (o.width < 0 || o.height < 0 || o.width > 16384 ||
             o.height > 16384) {
    err << "output.width/height must be in [0, 16384] px (0 = input size), "
           "got "
        << o.width << "x" << o.height;
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

Status OutputGeometry::Create(const CameraModel& model,
                              const OutputOptions& options,
                              OutputGeometry* out) {
  Status s = ValidateOutputOptions(options);
  if (!s.ok()) return s;
  const CameraIntrinsics& k = model.intrinsics();
  OutputGeometry g;
  g.width_ = options.width > 0 ? options.width : k.width;
  g.height_ = options.height > 0 ? options.height : k.height;
  g.f_v_ = model.virtual_focal();
  g.extent_y_ = k.height * (k.fx / k.fy) / k.width;
  *out = g.WithCropRatio(options.crop_ratio);
  return Status::Ok();
}

OutputGeometry OutputGeometry::WithCropRatio(double r) const {
  OutputGeometry g = *this;
  r = std::isfinite(r) ? std::min(std::max(r, 0.0), 0.4) : crop_ratio_;
  g.crop_ratio_ = r;
  g.margin_ = Eigen::Vector2d(r, r * extent_y_);
  g.half_extent_ = 0.5 * (1.0 - 2.0 * r) * Eigen::Vector2d(1.0, extent_y_);
  g.scale_ = Eigen::Vector2d(2.0 * g.half_extent_.x() / g.width_,
                             2.0 * g.half_extent_.y() / g.height_);
  return g;
}

Eigen::Vector2d OutputGeometry::OutputPixelToVirtual(
    const Eigen::Vector2d& uv) const {
  return Eigen::Vector2d(0.5 + (uv.x() + 0.5 - 0.5 * width_) * scale_.x(),
                         0.5 + (uv.y() + 0.5 - 0.5 * height_) * scale_.y());
}

Eigen::Vector2d OutputGeometry::VirtualToOutputPixel(
    const Eigen::Vector2d& V) const {
  return Eigen::Vector2d((V.x() - 0.5) / scale_.x() + 0.5 * width_ - 0.5,
                         (V.y() - 0.5) / scale_.y() + 0.5 * height_ - 0.5);
}

CameraIntrinsics OutputGeometry::VirtualIntrinsics(
    const Eigen::Vector2d& t) const {
  // V = f_v X/Z + 0.5 + t and u = (V - 0.5) / scale + (w - 1) / 2.
  CameraIntrinsics k;
  k.width = width_;
  k.height = height_;
  k.fx = f_v_ / scale_.x();
  k.fy = f_v_ / scale_.y();
  k.cx = t.x() / scale_.x() + 0.5 * (width_ - 1);
  k.cy = t.y() / scale_.y() + 0.5 * (height_ - 1);
  return k;
}

}  // namespace steadiface

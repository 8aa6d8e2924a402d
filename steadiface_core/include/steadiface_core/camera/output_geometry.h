#pragma once

#include <Eigen/Core>

#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/common/status.h"

namespace steadiface {

/// Output image geometry.
struct OutputOptions {
  /// The paper's r: fraction of the frame's width removed on the left and on
  /// the right, and of its height on the top and on the bottom [-]. The
  /// output keeps the central (1 - 2 r) of each dimension, so the default
  /// 0.15 (the paper's) keeps 70% of the width and of the height. It bounds
  /// how much shake can be removed: 0.1 suits gentle handheld walking, the
  /// paper's 0.15 also a recorded running trace (docs/evaluation.md). In
  /// [0, 0.4].
  double crop_ratio = 0.15;
  /// Output width [px]; 0 = input width.
  int width = 0;
  /// Output height [px]; 0 = input height.
  int height = 0;
};

Status ValidateOutputOptions(const OutputOptions& options);

/// Where output pixels sit in the virtual camera's normalized coordinates.
///
/// The crop window is centred on (0.5, 0.5) of the virtual image and spans
/// (1 - 2 r) of the real frame's normalized extent: 1 - 2r in x and
/// (1 - 2r) * H (fx/fy) / W in y. Output pixel centres tile that window with
/// the pixel-edge convention (the window's edges are the outer pixel edges),
/// so with f_v = f_r, R_v = R_r and t = 0 the output is exactly
/// cv::resize of the centre crop [rW, (1-r)W] x [rH, (1-r)H] (for a centred
/// principal point).
class OutputGeometry {
 public:
  static Status Create(const CameraModel& model, const OutputOptions& options,
                       OutputGeometry* out);

  OutputGeometry() = default;

  int width() const { return width_; }
  int height() const { return height_; }
  double crop_ratio() const { return crop_ratio_; }
  /// The same output (size, virtual focal length) with another crop ratio
  /// r in [0, 0.4] (the dynamic crop): the window, scaled about its centre,
  /// spans (1 - 2 r) of the frame. Out-of-range r is clamped.
  OutputGeometry WithCropRatio(double r) const;
  /// Crop margin per side in normalized units, x and y (the head smoother's
  /// r and the protrusion reference).
  Eigen::Vector2d margin() const { return margin_; }
  /// Half extent of the crop window in virtual normalized units.
  Eigen::Vector2d half_extent() const { return half_extent_; }

  /// Output pixel (u, v) -> virtual normalized V.
  Eigen::Vector2d OutputPixelToVirtual(const Eigen::Vector2d& uv) const;
  /// Virtual normalized V -> output pixel.
  Eigen::Vector2d VirtualToOutputPixel(const Eigen::Vector2d& V) const;

  /// Pinhole intrinsics of the output image for principal offset t: what the
  /// stabilized camera_info carries (no distortion: the warp removes it).
  CameraIntrinsics VirtualIntrinsics(const Eigen::Vector2d& t) const;

 private:
  int width_ = 0, height_ = 0;
  double crop_ratio_ = 0.0;
  double f_v_ = 1.0;
  double extent_y_ = 1.0;  // the frame's normalized height, H (fx/fy) / W
  Eigen::Vector2d margin_ = Eigen::Vector2d::Zero();
  Eigen::Vector2d half_extent_ = Eigen::Vector2d::Zero();
  // normalized units per output pixel, x and y
  Eigen::Vector2d scale_ = Eigen::Vector2d::Ones();
};

}  // namespace steadiface

#pragma once

#include <functional>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_intrinsics.h"

namespace steadiface {
namespace sim {

/// A real photo placed at infinity: world direction d (z forward) is textured
/// by the photo's pixel at  c + f_bg * (d_x / d_z, d_y / d_z), tiled by
/// mirroring so that no direction in front of the camera is ever empty.
class InfiniteBackground {
 public:
  /// `photo` is 8-bit BGR; `focal_px` is the texture's focal length (larger
  /// = more zoomed-in background detail).
  InfiniteBackground(const cv::Mat& photo, double focal_px);

  /// Texture coordinates (float pixels, before mirroring) of direction d.
  Eigen::Vector2d TextureCoords(const Eigen::Vector3d& d_world) const;

  /// Renders the view of a pinhole camera (no distortion) whose row y has the
  /// world->camera rotation R_of_row(y) (rolling shutter: call per row; a
  /// global shutter returns the same rotation). Bilinear sampling, mirrored
  /// tiling. Rows are evaluated in bands of `band_rows` rows (the rotation
  /// of the band's middle row) to keep rendering fast; 1 = exact per row.
  void Render(const CameraIntrinsics& k,
              const std::function<Eigen::Quaterniond(double)>& R_of_row,
              int band_rows, cv::Mat* out) const;

  const cv::Mat& photo() const { return photo_; }

 private:
  cv::Mat photo_;
  double focal_px_;
};

}  // namespace sim
}  // namespace steadiface

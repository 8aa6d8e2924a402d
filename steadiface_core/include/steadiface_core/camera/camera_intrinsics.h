#pragma once

#include <vector>

#include "steadiface_core/common/status.h"

namespace steadiface {

/// Lens distortion models, named as in sensor_msgs/CameraInfo.
enum class DistortionModel {
  kNone,        ///< no distortion (all coefficients zero or absent)
  kPlumbBob,    ///< "plumb_bob" / "rational_polynomial": k1 k2 p1 p2 k3 [k4 k5 k6]
  kEquidistant  ///< "equidistant" (fisheye): k1 k2 k3 k4
};

/// Calibrated pinhole intrinsics of the real camera, in the ROS/OpenCV pixel
/// convention: pixel centres sit at integer coordinates, x right, y down.
/// The ROS adapter fills this from sensor_msgs/CameraInfo (after binning/ROI).
struct CameraIntrinsics {
  /// Image width [px].
  int width = 0;
  /// Image height [px].
  int height = 0;
  /// Focal length along x [px].
  double fx = 0.0;
  /// Focal length along y [px].
  double fy = 0.0;
  /// Principal point x [px].
  double cx = 0.0;
  /// Principal point y [px].
  double cy = 0.0;
  /// Lens distortion model of `distortion_coeffs`.
  DistortionModel distortion = DistortionModel::kNone;
  /// Distortion coefficients, in the order of `distortion` (OpenCV order).
  std::vector<double> distortion_coeffs;

  /// True when the model is kNone or every coefficient is exactly zero.
  bool HasDistortion() const;
};

/// Intrinsics from a horizontal field of view, principal point at the image
/// centre ((w-1)/2, (h-1)/2), square pixels, no distortion.
CameraIntrinsics IntrinsicsFromHorizontalFov(int width, int height,
                                             double hfov_rad);

/// Checks sizes, finiteness and signs, and the coefficient count for the
/// distortion model. The message names the offending field.
Status ValidateIntrinsics(const CameraIntrinsics& intrinsics);

}  // namespace steadiface

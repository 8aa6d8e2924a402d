#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/camera/output_geometry.h"

namespace steadiface {

/// A pinhole camera of the composite: a rotation (world -> camera) and the
/// pixel intrinsics of its image.
struct LayerView {
  Eigen::Quaterniond R = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
};

/// K of pixel intrinsics (no distortion).
Eigen::Matrix3d PixelK(const CameraIntrinsics& k);

/// The view of an output image for a virtual pose (R_v, t): the
/// stabilized camera_info's intrinsics (OutputGeometry::VirtualIntrinsics).
LayerView OutputView(const OutputGeometry& output, const Eigen::Quaterniond& R_v,
                     const Eigen::Vector2d& t);

/// Pixel of `to` <- pixel of `from`: K_to R_to R_from^-1 K_from^-1. Exact
/// for the far scene: both views are of the same input rows, and each
/// rolling-shutter row's real rotation cancels between two virtual cameras.
Eigen::Matrix3d HomographyBetween(const LayerView& to, const LayerView& from);

/// For cv::warpPerspective(..., WARP_INVERSE_MAP): destination pixel of a
/// `dst` rectangle (origin at its corner, `scale_dst` destination pixels per
/// view pixel) -> source pixel of a `src` rectangle (`scale_src` likewise),
/// with H mapping view pixels of the destination to those of the source.
cv::Matx33d RectMap(const Eigen::Matrix3d& H_src_dst, const cv::Rect& src, double scale_src,
                    const cv::Rect& dst, double scale_dst);

/// The bounding box of `r`'s corners mapped by H (pixel centres), grown by
/// one pixel and clipped to `bounds`; empty when a corner is behind.
cv::Rect MapRect(const Eigen::Matrix3d& H, const cv::Rect& r, const cv::Rect& bounds);

}  // namespace steadiface

#pragma once

#include <functional>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/sim/background.h"

namespace steadiface {
namespace sim {

/// A rigid pose: rotation (local -> world) and position [m].
struct Pose {
  Eigen::Quaterniond R = Eigen::Quaterniond::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};

/// A textured planar quad (BGRA; alpha = coverage) in the world, e.g. a face
/// photo with a soft elliptical mask, or an occluding object. Its local frame
/// has x right and y down on the texture, z = 0 on the plane; the texture
/// centre `anchor_px` sits at the local origin.
struct Billboard {
  cv::Mat bgra;
  double metres_per_px = 0.001;
  Eigen::Vector2d anchor_px = Eigen::Vector2d::Zero();
  /// Pose at time t [s].
  std::function<Pose(double)> pose;
  /// A relief (CV_32F, one depth per texel along the local z, away from the
  /// viewer [m]; sim/head_relief.h): the board is then a surface, drawn with
  /// hidden parts removed. Empty: flat.
  cv::Mat depth_m;
  /// Texture point -> world point at time t (on the relief, if any).
  Eigen::Vector3d WorldPoint(const Eigen::Vector2d& uv, double t) const;
};

/// Makes a face billboard from a photo: crops `face_region` (px), applies a
/// soft elliptical alpha mask (feathered over `feather` of the radius) and
/// scales so the region is `width_m` wide.
Billboard MakeFaceBillboard(const cv::Mat& bgr_photo, const cv::Rect& face_region,
                            double width_m, double feather = 0.15);

/// Renders a pinhole camera (no distortion) with a rolling shutter: each band
/// of `band_rows` rows uses the camera pose of its middle row's time
/// `row_time(y)` (a relief billboard: each texel its own row's).
/// `camera_pose(t)` gives camera-to-world (x right, y down, z forward) at t.
/// Background at infinity first, then billboards in order (later ones in
/// front), alpha-blended.
void RenderScene(const CameraIntrinsics& k,
                 const std::function<double(double)>& row_time,
                 const std::function<Pose(double)>& camera_pose,
                 const InfiniteBackground& background,
                 const std::vector<const Billboard*>& billboards, int band_rows,
                 cv::Mat* out_bgr);

/// The coverage (alpha, CV_8UC1) of `billboards` alone, composited as
/// RenderScene composites them: the true matte of what they show.
void RenderAlpha(const CameraIntrinsics& k, const std::function<double(double)>& row_time,
                 const std::function<Pose(double)>& camera_pose,
                 const std::vector<const Billboard*>& billboards, int band_rows, cv::Mat* out);

/// Projects a world point into the camera at its own row (rolling-shutter
/// fixed point). Returns false behind the camera.
bool ProjectRollingShutter(const CameraIntrinsics& k,
                           const std::function<double(double)>& row_time,
                           const std::function<Pose(double)>& camera_pose,
                           const std::function<Eigen::Vector3d(double)>& point,
                           Eigen::Vector2d* pixel);

}  // namespace sim
}  // namespace steadiface

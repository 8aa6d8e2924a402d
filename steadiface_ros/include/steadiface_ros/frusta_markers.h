#pragma once

#include <deque>

#include <std_msgs/Header.h>
#include <visualization_msgs/MarkerArray.h>
#include <Eigen/Geometry>

#include "steadiface_core/camera/camera_intrinsics.h"

namespace steadiface_ros {

/// rviz markers that show the shake and its correction at a glance: the real
/// camera (orange) and the virtual camera (green) as frusta, each with its
/// image plane outlined and lightly filled at `depth` along the optical
/// axis, a label over each plane, and trails of the points where each
/// camera's optical axis meets that depth over the last `trail_length`
/// frames (jagged for the real camera, smooth for the virtual one).
///
/// Orientations are camera -> world (the inverse of the stabilizer's R_r and
/// R_v); the markers are expressed in the world frame of the header given.
class FrustaMarkers {
 public:
  explicit FrustaMarkers(size_t trail_length = 30, double depth_m = 1.0)
      : trail_length_(trail_length), depth_(depth_m) {}

  /// Records this frame's orientations in the trails (call every frame, so
  /// the trails are full when a viewer subscribes). Non-finite ones are
  /// skipped.
  void Add(const Eigen::Quaterniond& world_from_real,
           const Eigen::Quaterniond& world_from_virtual);
  /// Forgets the trails (time jumped back).
  void Clear();
  /// The marker array for the latest Add(); empty if there is none or an
  /// intrinsics is invalid.
  visualization_msgs::MarkerArray Make(
      const std_msgs::Header& world_header,
      const steadiface::CameraIntrinsics& real,
      const steadiface::CameraIntrinsics& virtual_camera) const;

  size_t trail_size() const { return real_trail_.size(); }

 private:
  const size_t trail_length_;
  const double depth_;
  std::deque<Eigen::Quaterniond> real_trail_, virtual_trail_;  // bounded
};

}  // namespace steadiface_ros

#pragma once

#include <vector>

#include <Eigen/Core>

namespace steadiface {

/// What the stabilizer needs to know about the face of interest in one
/// frame. Produced by the face tracker (or from external landmarks).
/// All positions are in the camera model's normalized coordinates of the
/// undistorted image.
struct FaceObservation {
  /// False when no face of interest is tracked in this frame.
  bool valid = false;
  /// Landmarks L_i [normalized].
  std::vector<Eigen::Vector2d> landmarks;
  /// Raw image row of each landmark [px] (rolling shutter: the row decides
  /// R_r). Empty = use the middle row.
  std::vector<double> landmark_rows;
  /// Landmark centre C = mean of L_i [normalized].
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  /// Face scale: RMS distance of the landmarks to C [normalized].
  double scale = 0.0;
  /// Tracking confidence in [0, 1].
  double confidence = 0.0;
  /// Whether yaw/pitch/roll below are valid.
  bool has_pose = false;
  /// Head pose relative to facing the camera [rad].
  double yaw = 0.0, pitch = 0.0, roll = 0.0;
};

/// Fills centre and scale from landmarks.
void ComputeCentreAndScale(FaceObservation* face);

/// Moves the face by `d` [normalized]: its landmarks and its centre.
void ShiftFace(const Eigen::Vector2d& d, FaceObservation* face);

}  // namespace steadiface

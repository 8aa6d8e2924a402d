#pragma once

#include <vector>

#include <Eigen/Core>

#include "steadiface_core/camera/camera_intrinsics.h"

namespace steadiface {

/// A 3D head model for PnP [m, head frame: x right, y down, z away from
/// the viewer]: x and y from a landmark model's mean 2D shape (so a face
/// the model sees frontally has zero pitch), scaled to 0.14 m between the
/// jaw ends and centred between the eyes; depth from GenericFace68.
std::vector<Eigen::Vector3d> BuildHeadModel(
    const std::vector<Eigen::Vector2d>& mean_shape);

/// Head pose relative to facing the camera, from cv::solvePnP of the 68
/// landmarks against a 3D head model (BuildHeadModel, or
/// GenericFace68 itself), relative to the line of sight (a face looking
/// straight into the camera has zero pose wherever it is in the image). With
/// R the head-to-line-of-sight rotation written as
/// R = Ry(yaw) Rx(pitch) Rz(roll) about the camera's axes (x right, y down,
/// z forward, right-handed), angles in [rad]. Returns false when PnP fails or the
/// result is non-finite.
bool EstimateHeadPose(const std::vector<Eigen::Vector3d>& model,
                      const std::vector<Eigen::Vector2d>& landmarks_px,
                      const CameraIntrinsics& intrinsics, double* yaw,
                      double* pitch, double* roll);

}  // namespace steadiface

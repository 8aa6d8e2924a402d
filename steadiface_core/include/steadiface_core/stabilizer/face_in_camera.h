#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/face/face_observation.h"
#include "steadiface_core/gyro/row_rotations.h"

namespace steadiface {

/// `face` as the camera (R_v, t) shows it, in *out: each landmark moved
/// through the real rotation of the row it was read on (rolling shutter), as
/// E_f moves them, and the centre and scale recomputed from the moved
/// landmarks; rows, confidence and pose kept. Landmarks without rows use
/// `R_r_middle`, the middle row's rotation.
///
/// Through the middle row's rotation alone, a face off the middle row would
/// be off by the rotation over the rows between (at 120 deg/s and a 30 ms
/// readout, about 1 deg for a face a quarter frame away), and that error
/// shakes with the camera. The stabilizer reads the face this way for Eq. 1's
/// C (in the predicted virtual view), for H's start, and as a world-fixed
/// camera sees it (the variation measure, and the face held after a loss).
///
/// False when the face has no landmarks or a landmark lies behind the camera
/// (that landmark is then left as it was in `face`).
bool FaceInCamera(const CameraModel& model, const FaceObservation& face,
                  const RowRotations& rows, const Eigen::Quaterniond& R_r_middle,
                  const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                  FaceObservation* out);

}  // namespace steadiface

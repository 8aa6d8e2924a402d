#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/gyro/row_rotations.h"
#include "steadiface_core/camera/output_geometry.h"

namespace steadiface {

/// The smallest crop ratio r in [0, 0.4] at which every output pixel of the
/// pose (R_v, t) maps inside the real frame, rolling shutter included: the
/// margin per side the pose uses, in the crop ratio's units (a fraction of
/// the frame's width, and of its height). 0.4 when even the narrowest window
/// is not defined.
///
/// The window at r is the output's scaled about its centre, so it is defined
/// for every r above the need (a smaller window lies inside a larger one);
/// the need is found by bisection, `steps` halvings of [0, 0.4], each a
/// ProtrusionGeometry check of `samples_per_edge` samples per edge.
double CropNeed(const CameraModel& model, const OutputGeometry& output,
                const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                const RowRotations& rows, int samples_per_edge = 8,
                int steps = 10);

}  // namespace steadiface

#pragma once

#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Transform.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Imu.h>

#include <Eigen/Geometry>

#include "steadiface_core/camera_intrinsics.h"
#include "steadiface_core/orientation_timeline.h"
#include "steadiface_core/status.h"

namespace steadiface_ros {

/// sensor_msgs/CameraInfo -> core intrinsics of the image as it arrives,
/// i.e. after the message's binning and region of interest are applied (as
/// image_geometry does). Rejects an uncalibrated info (K all zero), unknown
/// distortion models and inconsistent sizes with a message naming the field.
steadiface::Status ToCameraIntrinsics(const sensor_msgs::CameraInfo& info,
                                      steadiface::CameraIntrinsics* out);

/// sensor_msgs/Imu -> one gyro sample (stamp and angular_velocity). Values
/// are copied unchecked: the orientation timeline validates and counts them.
steadiface::GyroSample ToGyroSample(const sensor_msgs::Imu& imu);

/// Quaternion conversions. ToEigen normalizes; a zero or non-finite message
/// quaternion yields false.
bool ToEigen(const geometry_msgs::Quaternion& msg, Eigen::Quaterniond* q);
geometry_msgs::Quaternion ToMsg(const Eigen::Quaterniond& q);

/// A rotation-only transform.
geometry_msgs::Transform ToTransformMsg(const Eigen::Quaterniond& q);

}  // namespace steadiface_ros

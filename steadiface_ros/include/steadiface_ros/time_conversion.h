#pragma once

#include <ros/time.h>

#include "steadiface_core/common/time.h"

namespace steadiface_ros {

/// ros::Time -> the core's integer-nanosecond Time (exact).
steadiface::Time ToCoreTime(const ros::Time& t);

/// The core's Time -> ros::Time (exact). Times before the epoch, which
/// ros::Time cannot hold, clamp to ros::Time(0, 0).
ros::Time ToRosTime(steadiface::Time t);

/// ros::Duration -> core Duration (exact).
steadiface::Duration ToCoreDuration(const ros::Duration& d);

}  // namespace steadiface_ros

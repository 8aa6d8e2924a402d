#include "steadiface_ros/time_conversion.h"

namespace steadiface_ros {

steadiface::Time ToCoreTime(const ros::Time& t) {
  return steadiface::FromNanoseconds(static_cast<int64_t>(t.toNSec()));
}

ros::Time ToRosTime(steadiface::Time t) {
  const int64_t ns = steadiface::ToNanoseconds(t);
  ros::Time out;
  if (ns <= 0) return out;
  out.fromNSec(static_cast<uint64_t>(ns));
  return out;
}

steadiface::Duration ToCoreDuration(const ros::Duration& d) {
  return steadiface::Duration(d.toNSec());
}

}  // namespace steadiface_ros

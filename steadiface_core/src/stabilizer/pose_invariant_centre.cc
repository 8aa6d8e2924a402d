#include "steadiface_core/stabilizer/pose_invariant_centre.h"

#include <cmath>

namespace steadiface {

FaceObservation PoseInvariantCentre::Apply(const FaceObservation& face,
                                           double dt) {
  last_shift_ = 0.0;
  if (pivot_depth_ <= 0.0 || !face.valid || !face.has_pose ||
      !std::isfinite(face.yaw) || !(face.scale > 0.0)) {
    return face;
  }
  if (!has_yaw_ || !(dt > 0.0) || time_constant_s_ <= 0.0) {
    yaw_ = face.yaw;
  } else {
    const double a = std::exp(-std::min(dt, 1.0) / time_constant_s_);
    yaw_ = a * yaw_ + (1.0 - a) * face.yaw;
  }
  has_yaw_ = true;
  // The landmarks' centre sits at -d sin(yaw) (x right) from where it would
  // be facing the camera: moved back by +d sin(yaw).
  last_shift_ = pivot_depth_ * face.scale * std::sin(yaw_);
  FaceObservation out = face;
  for (Eigen::Vector2d& l : out.landmarks) l.x() += last_shift_;
  out.centre.x() += last_shift_;
  return out;
}

}  // namespace steadiface

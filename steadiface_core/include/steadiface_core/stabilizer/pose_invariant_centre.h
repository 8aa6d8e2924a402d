#pragma once

#include "steadiface_core/face/face_observation.h"
#include "steadiface_core/stabilizer/stabilizer_options.h"

namespace steadiface {

/// The pose-invariant head centre (ours). The paper (§4.4): "the virtual
/// camera will move when user is simply rotating the head. This is because
/// the 2D landmark center is not pose-invariant." A head turns about its
/// skull's centre, a depth d behind the landmarks' centre, so turning by yaw
/// swings the landmarks sideways by d sin(yaw). This moves them back by
/// d sin(yaw), d in face scales (`pose_pivot_depth` times the face's
/// scale), the yaw filtered causally by a one-euro filter: a low-pass of
/// time constant `pose_yaw_time_constant_s` that opens as the yaw's speed
/// rises (`pose_yaw_speed_gain`, `pose_yaw_speed_floor_rad_s`). Only the yaw:
/// PnP's pitch of a face against the generic model is biased by the face's
/// own proportions and noisier. Not thread-safe; one per stream.
class PoseInvariantCentre {
 public:
  explicit PoseInvariantCentre(const DynamicWeightOptions& options) : options_(options) {}
  /// Forgets the yaw (a face lost or a new epoch).
  void Reset() { has_yaw_ = false; }
  /// `face` (valid) with its landmarks and centre moved back by the turned
  /// face's offset from the skull's centre; `dt` is the time since the
  /// previous frame [s]. A face without a pose, or pivot_depth 0, is
  /// returned as it is.
  FaceObservation Apply(const FaceObservation& face, double dt);
  /// The last shift applied [normalized].
  double last_shift() const { return last_shift_; }

 private:
  // The filtered yaw after a new reading `yaw`, `dt` after the last.
  void FilterYaw(double yaw, double dt);

  DynamicWeightOptions options_;
  bool has_yaw_ = false;
  double yaw_ = 0.0, last_shift_ = 0.0;
  double yaw_speed_ = 0.0;  // filtered [rad/s]
};

}  // namespace steadiface

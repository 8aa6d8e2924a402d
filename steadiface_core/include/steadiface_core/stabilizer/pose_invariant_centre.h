#pragma once

#include "steadiface_core/face/face_observation.h"

namespace steadiface {

/// The pose-invariant head centre (ours). The paper (§4.4): "the virtual
/// camera will move when user is simply rotating the head. This is because
/// the 2D landmark center is not pose-invariant." A head turns about its
/// skull's centre, a depth d behind the landmarks' centre, so turning by yaw
/// swings the landmarks sideways by d sin(yaw). This moves them back by
/// d sin(yaw), d in face scales (`pivot_depth` times the face's scale), the
/// yaw low-passed causally (time constant `time_constant_s`). Only the yaw:
/// PnP's pitch of a face against the generic model is biased by the face's
/// own proportions and noisier. Not thread-safe; one per stream.
class PoseInvariantCentre {
 public:
  PoseInvariantCentre(double pivot_depth, double time_constant_s)
      : pivot_depth_(pivot_depth), time_constant_s_(time_constant_s) {}
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
  double pivot_depth_, time_constant_s_;
  bool has_yaw_ = false;
  double yaw_ = 0.0, last_shift_ = 0.0;
};

}  // namespace steadiface

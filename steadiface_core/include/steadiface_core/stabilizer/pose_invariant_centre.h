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
/// rises (`pose_yaw_speed_gain`, `pose_yaw_speed_floor_rad_s`). The nod
/// (pitch) moves the landmarks up and down the same way, but PnP's pitch of
/// a face against the generic model is offset by the face's own proportions
/// and about as noisy as a walking head's nod: only its part above a slow
/// mean (`pose_nod_time_constant_s`) is taken, low-passed as the yaw is, and
/// only `pose_nod_gain` of its shift, fading out as the face turns
/// (`pose_nod_max_yaw_rad`). Not thread-safe; one per stream.
class PoseInvariantCentre {
 public:
  explicit PoseInvariantCentre(const DynamicWeightOptions& options) : options_(options) {}
  /// Forgets the yaw and the pitch (a face lost or a new epoch).
  void Reset() { has_yaw_ = has_pitch_ = false; }
  /// `face` (valid) with its landmarks and centre moved back by the turned
  /// face's offset from the skull's centre; `dt` is the time since the
  /// previous frame [s]. A face without a pose, or pivot_depth 0, is
  /// returned as it is.
  FaceObservation Apply(const FaceObservation& face, double dt);
  /// The last shift applied, sideways (the turn) [normalized].
  double last_shift() const { return last_shift_; }
  /// The last shift applied, up or down (the nod) [normalized].
  double last_nod_shift() const { return last_nod_shift_; }

 private:
  // The filtered yaw after a new reading `yaw`, `dt` after the last.
  void FilterYaw(double yaw, double dt);
  // The nod after a new pitch reading, `dt` after the last: the low-passed
  // pitch less its slow mean [rad].
  double FilterNod(double pitch, double dt);

  DynamicWeightOptions options_;
  bool has_yaw_ = false;
  double yaw_ = 0.0, last_shift_ = 0.0, last_nod_shift_ = 0.0;
  bool has_pitch_ = false;
  double pitch_ = 0.0, pitch_mean_ = 0.0;  // low-passed, and its slow mean [rad]
  double yaw_speed_ = 0.0;  // filtered [rad/s]
};

}  // namespace steadiface

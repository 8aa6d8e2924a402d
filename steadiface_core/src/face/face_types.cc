#include "steadiface_core/face/face_types.h"

namespace steadiface {

const char* TrackingStateName(TrackingState s) {
  switch (s) {
    case TrackingState::kSearching:
      return "searching";
    case TrackingState::kTracking:
      return "tracking";
    case TrackingState::kLost:
      return "lost";
  }
  return "unknown";
}

const char* FaceFailureName(FaceFailure f) {
  switch (f) {
    case FaceFailure::kNone:
      return "none";
    case FaceFailure::kNoFace:
      return "no_face";
    case FaceFailure::kImplausibleShape:
      return "implausible_shape";
    case FaceFailure::kSpreadMismatch:
      return "spread_mismatch";
    case FaceFailure::kJump:
      return "jump";
    case FaceFailure::kAppearance:
      return "appearance";
    case FaceFailure::kOccluded:
      return "occluded";
    case FaceFailure::kOutOfFrame:
      return "out_of_frame";
    case FaceFailure::kBadInput:
      return "bad_input";
    case FaceFailure::kNotSearched:
      return "not_searched";
    case FaceFailure::kTurnMismatch:
      return "turn_mismatch";
  }
  return "unknown";
}

FaceObservation FaceInfo::ToObservation() const {
  FaceObservation o;
  o.valid = located();
  if (!o.valid) return o;
  o.landmarks = landmarks_normalized;
  o.landmark_rows.reserve(landmarks_px.size());
  for (const auto& p : landmarks_px) o.landmark_rows.push_back(p.y());
  o.centre = centre_normalized;
  o.scale = scale_normalized;
  o.confidence = confidence;
  o.has_pose = has_pose;
  o.yaw = yaw;
  o.pitch = pitch;
  o.roll = roll;
  return o;
}

}  // namespace steadiface

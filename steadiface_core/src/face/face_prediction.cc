// The face tracker's gyro prediction: where the last landmarks move with
// the camera's rotation between two frames (each at its own row's time).
#include "steadiface_core/face/face_tracker.h"

#include "face/landmark_shape.h"

namespace steadiface {

using namespace face_internal;  // NOLINT: the tracker's own helpers

Eigen::Quaterniond FaceTracker::MidRotation(Time stamp,
                                            const OrientationTimeline* tl,
                                            const RowTiming* timing,
                                            bool* ok) const {
  Eigen::Quaterniond R = Eigen::Quaterniond::Identity();
  *ok = false;
  if (tl == nullptr || timing == nullptr) return R;
  *ok = QuerySucceeded(tl->RealRotation(
      timing->RowTime(stamp, 0.5 * (model_.intrinsics().height - 1)), &R));
  return R;
}

bool FaceTracker::PredictLandmarks(Time stamp, const OrientationTimeline* tl,
                                   const RowTiming* timing,
                                   std::vector<Eigen::Vector2d>* predicted) const {
  *predicted = last_landmarks_;
  bool ok = false;
  const Eigen::Quaterniond R_now = MidRotation(stamp, tl, timing, &ok);
  if (!ok || !have_last_rotation_) return false;
  // A world-fixed face seen from the rotated camera: through the world
  // frame with the previous and the current real rotation.
  for (auto& p : *predicted) {
    Eigen::Vector2d m;
    if (SeenAfterRotation(p, last_rotation_, R_now, &m)) p = m;
  }
  return true;
}

bool FaceTracker::SeenAfterRotation(const Eigen::Vector2d& px, const Eigen::Quaterniond& R0,
                                    const Eigen::Quaterniond& R1, Eigen::Vector2d* out) const {
  const Eigen::Vector2d n = model_.PixelToNormalized(px);
  Eigen::Vector2d w, m;
  if (!model_.Project(n, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero(), R0, &w) ||
      !model_.Unproject(w, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero(), R1, &m)) {
    return false;
  }
  *out = model_.NormalizedToPixel(m);
  return true;
}

Eigen::Vector2d FaceTracker::CameraShift(const Eigen::Vector2d& from, Time stamp,
                                         const OrientationTimeline* tl,
                                         const RowTiming* timing) const {
  if (tl == nullptr || timing == nullptr || !have_last_frame_) return Eigen::Vector2d::Zero();
  Eigen::Quaterniond R0, R1;
  if (!QuerySucceeded(tl->RealRotation(timing->RowTime(last_frame_, from.y()), &R0)) ||
      !QuerySucceeded(tl->RealRotation(timing->RowTime(stamp, from.y()), &R1))) {
    return Eigen::Vector2d::Zero();
  }
  Eigen::Vector2d m;
  if (!SeenAfterRotation(from, R0, R1, &m)) return Eigen::Vector2d::Zero();
  const Eigen::Vector2d shift = m - from;
  return shift.allFinite() ? shift : Eigen::Vector2d::Zero();
}

}  // namespace steadiface

#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/face/face_observation.h"

namespace steadiface {

/// A detected face box in full-resolution pixels.
struct FaceBox {
  cv::Rect2d rect;
  /// Detector score (dlib HOG margin, or neighbour count for cascades).
  double score = 0.0;
};

/// Face-of-interest tracking state (paper §3.1).
enum class TrackingState {
  kSearching,  ///< no face locked; detecting over the whole frame
  kTracking,   ///< locked and landmarks valid this frame
  kLost,       ///< locked face not found; re-detecting near it until timeout
};

/// Why the last frame failed (kNone while tracking).
enum class FaceFailure {
  kNone = 0,
  kNoFace,            ///< nothing detected
  kImplausibleShape,  ///< landmarks do not look like a face
  kSpreadMismatch,    ///< landmarks' extent disagrees with the box
  kJump,              ///< centre jumped away from the gyro prediction
  kAppearance,        ///< face patch no longer looks like the locked face
  kOccluded,          ///< a region of the face patch (eyes, nose, mouth) does
                      ///< not: partly covered
  kOutOfFrame,        ///< the predicted box left the image
  kBadInput,          ///< empty / tiny / non-8-bit image, or bad landmarks
  kNotSearched,       ///< searching, but no full-frame detection this frame
                      ///< (face.search_interval)
  kTurnMismatch,      ///< a fit whose yaw disagrees with the followed turned
                      ///< head's: the landmark model's fit of a face still
                      ///< turned past what it fits
};

const char* TrackingStateName(TrackingState s);
const char* FaceFailureName(FaceFailure f);

struct FaceTimings {
  double detect_ms = 0.0;
  double landmarks_ms = 0.0;
  double checks_ms = 0.0;
  double pose_ms = 0.0;
  double total_ms = 0.0;
};

/// Everything known about the face of interest in one frame.
struct FaceInfo {
  TrackingState state = TrackingState::kSearching;
  FaceFailure failure = FaceFailure::kNone;
  /// True when `landmarks_*` hold this frame's validated landmarks.
  bool valid = false;
  /// True when the landmarks failed (`failure` says why) but the head,
  /// last seen turned away or partly covered, was followed by its image
  /// motion: `landmarks_*` hold the last fitted landmarks moved with it, a
  /// position and not a fit; the pose is the followed turn's, or a covered
  /// face's last fit's (FaceTrackerOptions::follow_turned_s,
  /// follow_covered_s).
  bool followed = false;
  /// Detection ran this frame (acquisition, periodic or after a failure).
  bool detected = false;
  /// Box the landmarks were fitted in [px].
  cv::Rect2d box;
  /// 68 landmarks in raw image pixels and in the camera model's normalized
  /// coordinates (undistorted).
  std::vector<Eigen::Vector2d> landmarks_px;
  std::vector<Eigen::Vector2d> landmarks_normalized;
  /// Landmark centre C and scale (RMS distance to C), pixels and normalized.
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d centre_normalized = Eigen::Vector2d::Zero();
  double scale_px = 0.0;
  double scale_normalized = 0.0;
  /// Confidence in [0, 1] (product of the check margins).
  double confidence = 0.0;
  /// Individual check values, for diagnostics.
  double shape_residual = 0.0;   ///< Procrustes RMS / scale vs the locked face
  double spread_ratio = 0.0;     ///< landmark extent / box size
  double jump = 0.0;             ///< |C - predicted C| / face scale
  double appearance = 0.0;       ///< NCC of the aligned face patch
  double region_appearance = 0.0;  ///< the lowest NCC of its regions (eyes, nose, mouth)
  /// Head pose from solvePnP against the generic 3D face [rad].
  bool has_pose = false;
  double yaw = 0.0, pitch = 0.0, roll = 0.0;
  /// Frames tracked since the lock, and seconds since the face was lost.
  int frames_tracked = 0;
  double lost_for_s = 0.0;
  FaceTimings timings;

  /// Where the face is known this frame: fitted or followed.
  bool located() const { return valid || followed; }
  /// What the stabilizer consumes (valid when located()).
  FaceObservation ToObservation() const;
};

}  // namespace steadiface

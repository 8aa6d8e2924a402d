// The face tracker's follow: a locked head whose landmarks fail, turned
// past what the landmark model fits or covered by a hand, followed by the
// image motion of its region (face/head_region_motion.h) as a turning
// cylinder (face/head_turn.h) or by its translation; the fits that may end
// it; the pose a covered face holds (the lock state machine:
// face_tracker.cc).
#include "steadiface_core/face/face_tracker.h"

#include <algorithm>
#include <cmath>

#include "face/landmark_shape.h"

namespace steadiface {

using namespace face_internal;  // NOLINT: the tracker's own helpers

namespace {
// A covered face's followed region reaches this share of the face box's
// height above it (forehead and hair) [-].
constexpr double kCoveredRegionUp = 0.4;
// ... and is measured from this many agreeing tracks: a hand leaves a strip
// of the face in view, and its tracks agree within 0.1 px on the
// simulator's hand (face_tracker_test) [-].
constexpr int kCoveredMinInliers = 6;
// A fit that would end a turned follow must read a yaw within this of the
// followed head's; else it is the landmark model's fit of a face still
// turned past what it fits (57 deg read as 21 deg on turn_away at 720p),
// and the follow goes on. At most kMaxRefitRejects such fits in a row are
// turned away, so a follow that drifted is still ended by the fits [rad].
constexpr double kRefitMaxYawChange = 0.4;
constexpr int kMaxRefitRejects = 3;
}  // namespace

bool FaceTracker::StartFollow(Time stamp, double scale) {
  // A face last fitted turned away whose landmarks now fail has most
  // likely turned past what the landmark model fits; its head is still in
  // view, and is followed as a turning cylinder (face/head_turn.h). A face
  // that fails while facing the camera is covered (a hand) or blurred; the
  // visible parts of its region still move with the head, and it is
  // followed by their translation, briefly, while they continue the head's
  // own motion (Follow's gate), so the tracker never follows the cover.
  // A cover starts in one region of a face that still looks like itself;
  // a face whose whole appearance had faded by its last fit is whipping
  // round faster than PnP's yaw shows, and is held.
  const double since_fit = ToSeconds(stamp - last_seen_);
  const bool turned = options_.follow_turned_s > 0.0 && have_fitted_pose_ && !past_profile_ &&
                      recent_abs_yaw_ >= options_.follow_min_yaw_rad &&
                      since_fit <= options_.follow_turned_s;
  const bool covered = options_.follow_covered_s > 0.0 && have_own_shift_ &&
                       fitted_appearance_ >= options_.follow_covered_min_appearance &&
                       (!have_fitted_pose_ || recent_abs_yaw_ < options_.follow_min_yaw_rad) &&
                       since_fit <= options_.follow_covered_s;
  if (following_) {
    if (following_covered_ ? covered : turned) return true;
  } else if (turned || covered) {
    following_covered_ = !turned;
    // The axis from the last fit: behind the landmark centre by the pivot
    // (a covered face: at its centre, followed by its translation).
    const double depth = following_covered_ ? 0.0 : options_.head_pivot_depth;
    head_turn_ = HeadTurn();
    head_turn_.radius_px = depth * scale;
    head_turn_.yaw = depth > 0.0 ? fitted_yaw_ : 0.0;
    // PnP's rate, within what one frame's turn may be (HeadTurn).
    head_turn_.yaw_rate = depth > 0.0 ? ClipTurnRate(fitted_yaw_rate_) : 0.0;
    head_turn_.axis_px =
        Mean(last_landmarks_) + Eigen::Vector2d(head_turn_.radius_px * std::sin(head_turn_.yaw), 0);
    return true;
  }
  return StopFollowing();
}

bool FaceTracker::RefitAgreesWithTurn(const Candidate& c) {
  if (!following_ || following_covered_ || !options_.estimate_head_pose) return true;
  double yaw = 0.0, pitch = 0.0, roll = 0.0;
  if (!Pose(c.landmarks, &yaw, &pitch, &roll) || !std::isfinite(yaw)) return true;
  if (std::abs(yaw - head_turn_.yaw) <= kRefitMaxYawChange || refit_rejects_ >= kMaxRefitRejects) {
    return true;
  }
  ++refit_rejects_;
  return false;
}

void FaceTracker::RememberPose(bool posed, bool consecutive, const FaceInfo& info) {
  if (!posed || !consecutive) recent_poses_ = 0;
  if (!posed) return;
  if (recent_poses_ == 3) {
    for (int i = 0; i < 2; ++i) {
      recent_yaws_[i] = recent_yaws_[i + 1];
      recent_pitches_[i] = recent_pitches_[i + 1];
    }
    --recent_poses_;
  }
  recent_yaws_[recent_poses_] = info.yaw;
  recent_pitches_[recent_poses_] = info.pitch;
  ++recent_poses_;
}

void FaceTracker::HeldPose(double* yaw, double* pitch) const {
  // A cover starts in one region of the face, and the last fits before the
  // landmarks fail are already dragged by it: PnP's pose of the last one
  // alone may be off by a spike. The median of the last three is not.
  if (recent_poses_ < 3) {
    *yaw = fitted_yaw_;
    *pitch = fitted_pitch_;
    return;
  }
  const auto median = [](const double* v) {
    return std::max(std::min(v[0], v[1]), std::min(std::max(v[0], v[1]), v[2]));
  };
  *yaw = median(recent_yaws_);
  *pitch = median(recent_pitches_);
}

bool FaceTracker::StopFollowing() {
  following_ = false;
  refit_rejects_ = 0;
  have_own_shift_ = false;
  return false;
}

bool FaceTracker::Follow(const cv::Mat& gray, Time stamp, const Eigen::Vector2d& pc,
                         const OrientationTimeline* timeline, const RowTiming* timing,
                         FaceInfo* info) {
  if (!region_motion_.ready() || fitted_landmarks_.empty()) {
    return StopFollowing();
  }
  const Eigen::Vector2d fitted_centre = Mean(fitted_landmarks_);
  const double scale = RmsRadius(fitted_landmarks_, fitted_centre);
  if (!(scale > 0.0) || !StartFollow(stamp, scale)) return false;
  // The head's own motion: the tracks beyond the camera's rotation; the
  // axis then moves by both.
  const HeadRegionMotion::CameraShift camera = [&](const Eigen::Vector2d& p) {
    return CameraShift(p, stamp, timeline, timing);
  };
  RegionFlow flow;
  HeadTurn next = head_turn_;
  const Eigen::Vector2d camera_at_axis = camera(next.axis_px);
  const int min_inliers =
      following_covered_ ? std::min(kCoveredMinInliers, options_.region_motion.min_inliers) : 0;
  bool moved = region_motion_.Track(gray, &flow, camera, min_inliers) &&
               (next.radius_px > 0.0 ? UpdateHeadTurn(flow, &next)
                                     : (next.axis_px += flow.mean_shift, true));
  // The region must move on as the head did: a median that does not is a
  // cover's motion (a hand that dragged the last landmarks into a turn, too).
  const double noise =
      have_own_change_ ? options_.follow_speed_change_noise * std::sqrt(own_change_ms_) : 0.0;
  const double gate = std::max({2.0, options_.follow_max_speed_change * scale, noise});
  if (have_own_shift_ && (flow.mean_shift - own_shift_).norm() > gate) moved = false;
  next.axis_px += camera_at_axis;
  const Eigen::Vector2d centre = next.FaceCentre();
  // A head turned past its profile is not followed further (the follow's
  // turn back from it drifts): it is held, and no follow starts again,
  // until the landmarks fit (StartFollow).
  if (next.past_profile) past_profile_ = true;
  if (!moved || next.past_profile || (centre - pc).norm() > options_.max_jump * scale) {
    return StopFollowing();
  }
  std::vector<Eigen::Vector2d> lm = fitted_landmarks_;
  for (auto& p : lm) p += centre - fitted_centre;
  // The region followed next: the head about its axis, the face's rows.
  const cv::Rect2d face = BoxFromLandmarks(lm);
  // A covered face's region reaches up over the forehead and hair, which
  // a hand over the face mostly leaves in view.
  const double half = next.radius_px > 0.0 ? 0.9 * next.radius_px : 0.5 * face.width;
  const double up = following_covered_ ? kCoveredRegionUp * face.height : 0.0;
  const cv::Rect2d head(next.axis_px.x() - half, face.y - up, 2.0 * half, face.height + up);
  if ((head & cv::Rect2d(0, 0, gray.cols, gray.rows)).area() < 0.5 * head.area()) {
    return StopFollowing();
  }
  following_ = true;
  head_turn_ = next;
  own_shift_ = flow.mean_shift;
  have_own_shift_ = true;
  last_landmarks_ = lm;
  last_located_ = stamp;
  region_motion_.Remember(gray, head);
  info->followed = true;
  info->box = face;
  Fill(lm, info);
  info->confidence = flow.inlier_share;
  info->has_pose = true;
  // A covered face moves by its visible parts' translation: its turn is not
  // seen, and is held at the last fits' (not 0, which would swing the
  // pose-invariant centre by its pivot's offset from the landmarks).
  info->yaw = head_turn_.yaw;
  info->pitch = fitted_pitch_;
  if (following_covered_) HeldPose(&info->yaw, &info->pitch);
  info->roll = fitted_roll_;
  return true;
}

}  // namespace steadiface

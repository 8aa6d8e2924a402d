// FaceTrackerOptions' checks.
#include "steadiface_core/face/face_tracker.h"

#include <cmath>
#include <sstream>

namespace steadiface {

Status ValidateFaceTrackerOptions(const FaceTrackerOptions& o) {
  Status s = ValidateFaceDetectorOptions(o.detector);
  if (!s.ok()) return s;
  std::ostringstream err;
  if (o.redetect_every_frames < 1 || o.redetect_every_frames > 10000) {
    err << "face.redetect_every must be in [1, 10000] frames, got "
        << o.redetect_every_frames;
  } else if (!(o.redetect_region_scale >= 1.0 && o.redetect_region_scale <= 10.0)) {
    err << "face.redetect_region_scale must be in [1, 10], got "
        << o.redetect_region_scale;
  } else if (o.redetect_face_px < 60 || o.redetect_face_px > 1000) {
    err << "face.redetect_face_px must be in [60, 1000], got " << o.redetect_face_px;
  } else if (o.small_face_fit_px < 0 || o.small_face_fit_px > 1000) {
    err << "face.small_face_fit_px must be in [0, 1000], got " << o.small_face_fit_px;
  } else if (!(o.lost_timeout_s >= 0.0 && o.lost_timeout_s <= 60.0)) {
    err << "face.lost_timeout must be in [0, 60] s, got " << o.lost_timeout_s;
  } else if (!(o.search_interval_s >= 0.0 && o.search_interval_s <= 10.0)) {
    err << "face.search_interval must be in [0, 10] s, got " << o.search_interval_s;
  } else if (!(o.max_shape_residual > 0.0 && o.max_shape_residual <= 2.0)) {
    err << "face.max_shape_residual must be in (0, 2], got " << o.max_shape_residual;
  } else if (!(o.min_spread_ratio > 0.0 && o.min_spread_ratio < o.max_spread_ratio &&
               o.max_spread_ratio <= 10.0)) {
    err << "face.min_spread_ratio/max_spread_ratio must satisfy 0 < min < max <= 10, got "
        << o.min_spread_ratio << "/" << o.max_spread_ratio;
  } else if (!(o.max_jump > 0.0 && o.max_jump <= 20.0)) {
    err << "face.max_jump must be in (0, 20], got " << o.max_jump;
  } else if (!(o.min_appearance >= -1.0 && o.min_appearance < 1.0)) {
    err << "face.min_appearance must be in [-1, 1), got " << o.min_appearance;
  } else if (!(o.min_region_appearance >= -1.0 && o.min_region_appearance < 1.0)) {
    err << "face.min_region_appearance must be in [-1, 1), got " << o.min_region_appearance;
  } else if (o.appearance_patch_px < 16 || o.appearance_patch_px > 256) {
    err << "face.appearance_patch_px must be in [16, 256], got " << o.appearance_patch_px;
  } else if (!(o.relock_yaw_step_rad >= 0.0 && o.relock_yaw_step_rad <= 1.0)) {
    err << "face.relock_yaw_step_rad must be in [0, 1], got " << o.relock_yaw_step_rad;
  } else if (!(o.follow_turned_s >= 0.0 && o.follow_turned_s <= 60.0)) {
    err << "face.follow_turned must be in [0, 60] s, got " << o.follow_turned_s;
  } else if (!(o.follow_covered_s >= 0.0 && o.follow_covered_s <= 10.0)) {
    err << "face.follow_covered must be in [0, 10] s, got " << o.follow_covered_s;
  } else if (!(o.follow_covered_min_appearance >= 0.0 && o.follow_covered_min_appearance <= 1.0)) {
    err << "face.follow_covered_min_appearance must be in [0, 1], got "
        << o.follow_covered_min_appearance;
  } else if (!(o.follow_speed_change_noise >= 0.0 && o.follow_speed_change_noise <= 100.0)) {
    err << "face.follow_speed_change_noise must be in [0, 100], got "
        << o.follow_speed_change_noise;
  } else if (!(o.follow_max_speed_change > 0.0 && o.follow_max_speed_change <= 10.0)) {
    err << "face.follow_max_speed_change must be in (0, 10] face scales per frame, got "
        << o.follow_max_speed_change;
  } else if (!(o.follow_min_yaw_rad >= 0.0 && o.follow_min_yaw_rad <= 1.6)) {
    err << "face.follow_min_yaw must be in [0, 1.6] rad, got " << o.follow_min_yaw_rad;
  } else if (!(o.head_pivot_depth >= 0.0 && o.head_pivot_depth <= 10.0)) {
    err << "face.head_pivot_depth must be in [0, 10] face scales, got " << o.head_pivot_depth;
  } else if (o.region_motion.max_features < 4 || o.region_motion.max_features > 1000 ||
             o.region_motion.min_inliers < 3 ||
             o.region_motion.min_inliers > o.region_motion.max_features) {
    err << "face.region_motion: need 3 <= min_inliers <= max_features <= 1000, got "
        << o.region_motion.min_inliers << " / " << o.region_motion.max_features;
  } else if (!(o.region_motion.max_forward_backward_px > 0.0) ||
             !(o.region_motion.inlier_share > 0.0) ||
             !(o.region_motion.max_region_px >= 32.0) ||
             !(o.region_motion.search_margin >= 0.1 && o.region_motion.search_margin <= 3.0)) {
    err << "face.region_motion: max_forward_backward_px and inlier_share must be > 0, "
           "max_region_px >= 32, search_margin in [0.1, 3]";
  } else if (!(o.appearance_update_rate >= 0.0 && o.appearance_update_rate <= 1.0)) {
    err << "face.appearance_update_rate must be in [0, 1], got "
        << o.appearance_update_rate;
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

}  // namespace steadiface

// The face tracker's candidate gate: a fitted face is accepted only if its
// landmarks are finite, ordered, plausibly shaped and sized, near where the
// gyro says, and (when locked) it looks like the locked face.
#include "steadiface_core/face/face_tracker.h"

#include <algorithm>
#include <cmath>

#include "face/landmark_shape.h"
#include "steadiface_core/face/head_pose.h"
#include "steadiface_core/face/landmarks68.h"

namespace steadiface {

using namespace face_internal;  // NOLINT: the tracker's own helpers

cv::Rect2d FaceTracker::BoxFromLandmarks(const std::vector<Eigen::Vector2d>& lm) const {
  const cv::Rect2d e = Extent(lm);
  const double cx = e.x + 0.5 * e.width + box_model_[0] * e.width;
  const double cy = e.y + 0.5 * e.height + box_model_[1] * e.height;
  const double w = box_model_[2] * e.width, h = box_model_[3] * e.height;
  return cv::Rect2d(cx - 0.5 * w, cy - 0.5 * h, w, h);
}

void FaceTracker::Fill(const std::vector<Eigen::Vector2d>& lm, FaceInfo* info) const {
  info->landmarks_px = lm;
  info->landmarks_normalized.resize(lm.size());
  for (size_t i = 0; i < lm.size(); ++i) {
    model_.RawPixelToNormalized(lm[i], &info->landmarks_normalized[i]);
  }
  info->centre_px = Mean(lm);
  info->scale_px = RmsRadius(lm, info->centre_px);
  info->centre_normalized = Mean(info->landmarks_normalized);
  info->scale_normalized = RmsRadius(info->landmarks_normalized, info->centre_normalized);
}

bool FaceTracker::Evaluate(const cv::Mat* gray, const Candidate& c, bool acquiring,
                           const Eigen::Vector2d* predicted_centre,
                           FaceInfo* info, cv::Mat* patch) const {
  const auto t0 = Clock::now();
  FaceFailure fail = FaceFailure::kNone;
  double score_sum = 0.0;
  int n_scores = 0;
  if (c.landmarks.size() != landmarks68::kCount || !AllFinite(c.landmarks)) {
    fail = FaceFailure::kBadInput;
  }
  const Eigen::Vector2d centre = Mean(c.landmarks);
  const double scale = RmsRadius(c.landmarks, centre);
  if (fail == FaceFailure::kNone && scale < 3.0) fail = FaceFailure::kImplausibleShape;
  // 1. Shape plausibility against the locked face (or, at acquisition,
  // basic symmetry: eyes above the mouth, left-right ordered).
  if (fail == FaceFailure::kNone) {
    const auto& lm = c.landmarks;
    namespace l68 = landmarks68;
    const bool ordered = lm[l68::kRightEyeOuter].x() < lm[l68::kLeftEyeOuter].x() &&
                         lm[l68::kNoseBridgeTop].y() < lm[l68::kLowerLipBottom].y() &&
                         lm[l68::kJawRightEnd].x() < lm[l68::kJawLeftEnd].x() &&
                         lm[l68::kMouthRight].x() < lm[l68::kMouthLeft].x();
    info->shape_residual = acquiring || reference_shape_.empty()
                               ? 0.0
                               : ProcrustesResidual(Normalize(lm), reference_shape_);
    if (!ordered || info->shape_residual > options_.max_shape_residual) {
      fail = FaceFailure::kImplausibleShape;
    } else {
      score_sum += 1.0 - info->shape_residual / options_.max_shape_residual;
      ++n_scores;
    }
  }
  // 2. Spread vs the box.
  if (fail == FaceFailure::kNone) {
    const cv::Rect2d e = Extent(c.landmarks);
    info->spread_ratio = std::sqrt(e.area() / std::max(1.0, c.box.area()));
    if (info->spread_ratio < options_.min_spread_ratio ||
        info->spread_ratio > options_.max_spread_ratio) {
      fail = FaceFailure::kSpreadMismatch;
    } else {
      const double mid = 0.5 * (options_.min_spread_ratio + options_.max_spread_ratio);
      const double half = 0.5 * (options_.max_spread_ratio - options_.min_spread_ratio);
      score_sum += 1.0 - std::abs(info->spread_ratio - mid) / half;
      ++n_scores;
    }
  }
  // 3. Jump vs the gyro-compensated prediction (relaxed while lost: the face
  // may have moved while it was not seen).
  if (fail == FaceFailure::kNone && predicted_centre != nullptr && !acquiring) {
    const double limit =
        options_.max_jump * (state_ == TrackingState::kLost ? 3.0 : 1.0);
    info->jump = (centre - *predicted_centre).norm() / scale;
    if (info->jump > limit) {
      fail = FaceFailure::kJump;
    } else {
      score_sum += 1.0 - info->jump / limit;
      ++n_scores;
    }
  }
  // 4. Appearance: the aligned face patch against the locked face's.
  if (fail == FaceFailure::kNone && gray != nullptr) {
    fail = CheckAppearance(*gray, c, acquiring, info, patch, &score_sum, &n_scores);
  }
  info->timings.checks_ms += MsSince(t0);
  info->failure = fail;
  info->confidence =
      fail == FaceFailure::kNone
          ? std::min(1.0, std::max(0.0, 0.5 + 0.5 * (n_scores ? score_sum / n_scores : 1.0)))
          : 0.0;
  return fail == FaceFailure::kNone;
}

}  // namespace steadiface

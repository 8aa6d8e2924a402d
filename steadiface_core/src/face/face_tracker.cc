// The face tracker's lock state machine: search, acquire, track, hold and
// lose the face of interest (the gate: face_candidate.cc; the gyro
// prediction: face_prediction.cc; appearance: face_appearance.cc; the
// follow of a turned or covered head: face_follow.cc).
#include "steadiface_core/face/face_tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "face/landmark_shape.h"
#include "steadiface_core/camera/lens_distortion.h"
#include "steadiface_core/common/grey.h"
#include "steadiface_core/face/head_pose.h"
#include "steadiface_core/face/landmarks68.h"
#include "steadiface_core/face/upsampled_fit.h"

namespace steadiface {

using namespace face_internal;  // NOLINT: the tracker's own helpers

namespace {
// Follow's gate forgets a turn at this rate [rad/s].
constexpr double kTurnMemoryRadPerS = 0.3;
// While a head is followed, the detector runs on one frame in this many.
constexpr int kFollowRedetectFrames = 3;
// The gain of the first-order filter on PnP's yaw change between
// consecutive fits: the rate a follow starts from [-].
constexpr double kFittedYawRateGain = 0.7;
// A fit whose regions disagree (a cover over part of the face) and whose
// yaw leaves the trend of the two fits before it by more than this (the
// second difference of the three) was dragged by the cover [rad]. The hand
// of `occlusion` at twice the head's motion, seeds 1-3, dragged the last
// fit by 0.12-0.17 rad; on the other fits whose regions disagreed (mostly
// a turning face: turn_away with the relief and the mean-face heads and
// turning twice as fast, occlusion at up to three times and walk at up to
// twice the head's motion, seeds 1-3) the second difference was at most
// 0.06 (docs/evaluation.md).
constexpr double kDraggedYawJump = 0.09;
}  // namespace

Status FaceTracker::Create(const CameraModel& model,
                           const FaceTrackerOptions& options,
                           std::unique_ptr<FaceTracker>* out) {
  Status s = ValidateFaceTrackerOptions(options);
  if (!s.ok()) return s;
  std::unique_ptr<FaceTracker> t(new FaceTracker(model, options));
  s = FaceDetector::Create(options.detector, &t->detector_);
  if (!s.ok()) return s;
  s = LandmarkPredictor::Load(options.landmark_model_path, &t->predictor_);
  if (!s.ok()) return s;
  t->head_model_ = BuildHeadModel(t->predictor_->MeanShape());
  const CameraIntrinsics& k = model.intrinsics();
  t->schedule_.reset(new SearchSchedule(cv::Size(k.width, k.height),
                                        options.detector.max_side_px,
                                        t->detector_->window_px(),
                                        options.detector.min_face_px,
                                        options.search_interval_s));
  *out = std::move(t);
  return Status::Ok();
}

FaceTracker::FaceTracker(const CameraModel& model,
                         const FaceTrackerOptions& options)
    : model_(model), options_(options) {}

void FaceTracker::Reset() {
  state_ = TrackingState::kSearching;
  if (schedule_) schedule_->Restart();
  last_landmarks_.clear();
  reference_shape_.clear();
  reference_patch_.release();
  reference_yaw_ = 0.0;
  region_motion_.Clear();
  following_ = false;
  past_profile_ = false;
  have_own_shift_ = false;
  have_own_change_ = false;
  own_change_ms_ = 0.0;
  have_last_frame_ = false;
  fitted_last_frame_ = false;
  have_fitted_pose_ = false;
  recent_poses_ = 0;
  refit_rejects_ = 0;
  recent_abs_yaw_ = 0.0;
  fitted_appearance_ = 1.0;
  have_last_rotation_ = false;
  frames_since_detect_ = 0;
  frames_tracked_ = 0;
  force_detect_ = true;
}

void FaceTracker::Accept(const Candidate& c, bool acquiring, const cv::Mat& patch,
                         Time stamp, FaceInfo* info) {
  const bool after_fit = fitted_last_frame_;
  const Time previous_fit = last_seen_;
  fitted_last_frame_ = true;
  if (acquiring) {
    reference_shape_ = Normalize(c.landmarks);
    reference_patch_ = patch.empty() ? cv::Mat() : patch.clone();
    frames_tracked_ = 0;
  } else if (!patch.empty() && !reference_patch_.empty()) {
    cv::addWeighted(reference_patch_, 1.0 - options_.appearance_update_rate, patch,
                    options_.appearance_update_rate, 0.0, reference_patch_);
  }
  if (c.detected) {
    // Learn how detector boxes sit on the landmarks, for tracking boxes.
    const cv::Rect2d e = Extent(c.landmarks);
    if (e.width > 1 && e.height > 1) {
      const Eigen::Vector4d m((c.box.x + 0.5 * c.box.width - (e.x + 0.5 * e.width)) / e.width,
                              (c.box.y + 0.5 * c.box.height - (e.y + 0.5 * e.height)) / e.height,
                              c.box.width / e.width, c.box.height / e.height);
      box_model_ = acquiring ? m : 0.5 * (box_model_ + m);
    }
  }
  last_landmarks_ = c.landmarks;
  fitted_landmarks_ = c.landmarks;
  following_ = false;
  refit_rejects_ = 0;
  past_profile_ = false;
  last_seen_ = stamp;
  last_located_ = stamp;
  state_ = TrackingState::kTracking;
  force_detect_ = false;
  ++frames_tracked_;
  info->state = state_;
  info->valid = true;
  info->detected = info->detected || c.detected;
  info->box = c.box;
  info->frames_tracked = frames_tracked_;
  Fill(c.landmarks, info);
  if (options_.estimate_head_pose) {
    const auto t0 = Clock::now();
    info->has_pose = Pose(c.landmarks, &info->yaw, &info->pitch, &info->roll);
    info->timings.pose_ms = MsSince(t0);
  }
  const bool posed = info->has_pose && std::isfinite(info->yaw);
  // The turn's rate over consecutive fits, for a turn followed on.
  const bool consecutive = posed && have_fitted_pose_ && !acquiring && after_fit;
  fitted_yaw_rate_ =
      consecutive ? fitted_yaw_rate_ + kFittedYawRateGain * (info->yaw - fitted_yaw_ - fitted_yaw_rate_)
                  : 0.0;
  have_fitted_pose_ = posed;
  // Without a patch (external landmarks) the appearance was not measured.
  fitted_appearance_ = patch.empty() ? 1.0 : info->appearance;
  RememberPose(posed, consecutive, *info);
  fitted_yaw_ = info->yaw;
  fitted_pitch_ = info->pitch;
  fitted_roll_ = info->roll;
  // How far the face turned lately: the largest fitted |yaw|, forgotten at
  // kTurnMemoryRadPerS (PnP's yaw is noisy frame to frame). A hand arriving
  // over the face drags the landmarks into a spike of yaw, which would
  // start the follow of a turned head instead of a covered one: a fit whose
  // regions disagree (RegionAppearance < 1; measured only with a patch, not
  // for external landmarks) and whose yaw jumps off the trend
  // (kDraggedYawJump) counts with the median of the last three fits' yaw
  // (HeldPose).
  double turn = info->yaw, pitch = 0.0;
  const bool dragged =
      !patch.empty() && info->region_appearance < 1.0 && recent_poses_ == 3 &&
      std::abs(recent_yaws_[2] - 2.0 * recent_yaws_[1] + recent_yaws_[0]) > kDraggedYawJump;
  if (dragged) HeldPose(&turn, &pitch);
  const double dt = acquiring ? 1e9 : std::max(0.0, ToSeconds(stamp - previous_fit));
  recent_abs_yaw_ = std::max(posed ? std::abs(turn) : 0.0,
                             recent_abs_yaw_ - kTurnMemoryRadPerS * std::min(dt, 10.0));
  Relock(c, acquiring, patch, *info);
}

void FaceTracker::Relock(const Candidate& c, bool acquiring, const cv::Mat& patch,
                         const FaceInfo& info) {
  // The references follow the face towards the camera (never away from it).
  // A lock without a pose counts as frontal: it is never re-taken.
  const bool posed = info.has_pose && std::isfinite(info.yaw);
  if (acquiring) {
    reference_yaw_ = posed ? std::abs(info.yaw) : 0.0;
  } else if (posed && options_.relock_yaw_step_rad > 0.0 &&
             std::abs(info.yaw) < reference_yaw_ - options_.relock_yaw_step_rad) {
    reference_shape_ = Normalize(c.landmarks);
    if (!patch.empty()) reference_patch_ = patch.clone();
    reference_yaw_ = std::abs(info.yaw);
  }
}

void FaceTracker::MarkFailure(FaceFailure f, Time stamp, FaceInfo* info) {
  fitted_last_frame_ = false;
  if (state_ == TrackingState::kTracking) state_ = TrackingState::kLost;
  force_detect_ = true;
  info->state = state_;
  info->valid = false;
  info->failure = f;
  info->confidence = 0.0;
  info->landmarks_px.clear();
  info->landmarks_normalized.clear();
  if (state_ == TrackingState::kLost) info->lost_for_s = ToSeconds(stamp - last_seen_);
}

bool FaceTracker::DetectAndFit(const cv::Mat& gray, const cv::Rect& roi,
                               const cv::Rect2d* near, Candidate* c,
                               double* detect_ms) {
  const auto t0 = Clock::now();
  std::vector<FaceBox> faces;
  // Scale so the expected face is ~redetect_face_px wide: down in whole
  // pixels of the copy's longest side, or up for a small face (at most so
  // far that the smallest face searched for fills the detector's window).
  const int longest = std::max(roi.width, roi.height);
  auto down = [&](double side) {
    return side < longest ? static_cast<int>(side) / static_cast<double>(longest) : 1.0;
  };
  double scale = 0.0;
  if (near != nullptr && near->width > 0) {
    scale = options_.redetect_face_px / near->width;
    scale = scale < 1.0 ? down(std::max(64.0, longest * scale))
                        : std::min(scale, std::max(1.0, detector_->window_px() /
                                                            options_.detector.min_face_px));
  }
  bool ok = detector_->Detect(gray, roi, &faces, scale).ok();
  if (ok && faces.empty() && scale > 0.0) {
    // A second scale near the expected face: blur and rolling-shutter skew
    // defeat the HOG detector at one scale more often than at two.
    const double second =
        scale < 1.0 ? down(std::floor(scale * longest + 0.5) * 1.6) : 1.6 * scale;
    ok = detector_->Detect(gray, roi, &faces, second).ok();
  }
  *detect_ms += MsSince(t0);
  if (!ok || faces.empty()) return false;
  const FaceBox* best = &faces.front();  // largest
  if (near != nullptr) {
    best = nullptr;
    double best_d = 1e18;
    const Eigen::Vector2d nc(near->x + 0.5 * near->width, near->y + 0.5 * near->height);
    for (const auto& f : faces) {
      const Eigen::Vector2d fc(f.rect.x + 0.5 * f.rect.width, f.rect.y + 0.5 * f.rect.height);
      const double d = (fc - nc).norm();
      if (d < std::max(near->width, near->height) && d < best_d) {
        best_d = d;
        best = &f;
      }
    }
    if (best == nullptr) return false;
  }
  c->box = best->rect;
  c->detected = true;
  return Fit(gray, c->box, &c->landmarks);
}

bool FaceTracker::Fit(const cv::Mat& gray, const cv::Rect2d& box,
                      std::vector<Eigen::Vector2d>* landmarks) const {
  return FitLandmarksUpsampled(*predictor_, gray, box, options_.small_face_fit_px, landmarks)
      .ok();
}

Status FaceTracker::Process(const cv::Mat& image, Time stamp,
                            const OrientationTimeline* timeline,
                            const RowTiming* timing, FaceInfo* info) {
  const auto t_start = Clock::now();
  *info = FaceInfo();
  info->state = state_;
  const CameraIntrinsics& k = model_.intrinsics();
  if (image.empty() || image.depth() != CV_8U ||
      (image.channels() != 1 && image.channels() != 3 && image.channels() != 4) ||
      image.cols != k.width || image.rows != k.height) {
    info->failure = FaceFailure::kBadInput;
    std::ostringstream err;
    err << "face: need an 8-bit 1/3/4-channel " << k.width << "x" << k.height
        << " image, got " << image.cols << "x" << image.rows << " type "
        << image.type();
    return Status::Error(err.str());
  }
  const cv::Mat gray = ToGrey(image);
  bool rot_ok = false;
  const Eigen::Quaterniond R_now = MidRotation(stamp, timeline, timing, &rot_ok);
  const cv::Rect full(0, 0, gray.cols, gray.rows);

  if (state_ == TrackingState::kLost &&
      ToSeconds(stamp - last_located_) > options_.lost_timeout_s) {
    Reset();
  }
  // While searching, the whole frame once per search_interval_s and a
  // small-face tile in between (face/search_schedule.h).
  SearchStep step;
  if (state_ == TrackingState::kSearching && !schedule_->Due(stamp, &step)) {
    MarkFailure(FaceFailure::kNotSearched, stamp, info);
  } else if (state_ == TrackingState::kSearching) {
    Search(gray, step, stamp, info);
  } else {
    Track(gray, full, stamp, timeline, timing, rot_ok, info);
  }
  last_frame_ = stamp;
  have_last_frame_ = true;
  // Periodic re-detection counts from the last attempt, found or not.
  frames_since_detect_ = info->detected ? 0 : frames_since_detect_ + 1;
  if (rot_ok && !last_landmarks_.empty()) {
    last_rotation_ = R_now;
    have_last_rotation_ = true;
  } else if (!rot_ok) {
    have_last_rotation_ = false;
  }
  info->timings.total_ms = MsSince(t_start);
  return Status::Ok();
}

void FaceTracker::Search(const cv::Mat& gray, const SearchStep& step, Time stamp,
                         FaceInfo* info) {
  // One step of the search schedule (the whole frame, or an upsampled
  // tile for small faces); the largest face whose landmarks pass the
  // checks is locked.
  Candidate c;
  cv::Mat patch;
  bool ok = false;
  const auto t0 = Clock::now();
  std::vector<FaceBox> faces;
  // A region the detector refuses (outside the frame) finds no face.
  if (!detector_->Detect(gray, step.roi, &faces, step.scale).ok()) faces.clear();
  info->timings.detect_ms += MsSince(t0);
  info->detected = true;
  for (const FaceBox& f : faces) {  // largest first
    c = Candidate();
    c.box = f.rect;
    c.detected = true;
    const auto t1 = Clock::now();
    const bool fit = Fit(gray, c.box, &c.landmarks);
    info->timings.landmarks_ms += MsSince(t1);
    if (fit && Evaluate(&gray, c, true, nullptr, info, &patch)) {
      ok = true;
      break;
    }
  }
  if (ok) {
    TakeFit(gray, c, true, patch, nullptr, stamp, info);
  } else {
    MarkFailure(faces.empty() ? FaceFailure::kNoFace : info->failure, stamp, info);
  }
}

void FaceTracker::TakeFit(const cv::Mat& gray, const Candidate& c, bool acquiring,
                          const cv::Mat& patch, const Eigen::Vector2d* predicted_centre,
                          Time stamp, FaceInfo* info) {
  // The head's own motion, for the follow's gate: the centre against where
  // the camera's rotation alone would have put it, when the face was
  // located in the frame before too.
  const bool had_own_shift = have_own_shift_ && !following_;
  const Eigen::Vector2d previous = own_shift_;
  have_own_shift_ = predicted_centre != nullptr && (fitted_last_frame_ || following_);
  if (have_own_shift_) own_shift_ = Mean(c.landmarks) - *predicted_centre;
  // How much that motion changes between fitted frames: the follow's gate
  // widens for a head that jitters (never from followed frames, where a
  // cover's motion could widen it).
  if (had_own_shift && have_own_shift_) {
    constexpr double kRate = 0.1;  // about the last 10 fitted frames
    const double d2 = (own_shift_ - previous).squaredNorm();
    own_change_ms_ = have_own_change_ ? (1.0 - kRate) * own_change_ms_ + kRate * d2 : d2;
    have_own_change_ = true;
  }
  Accept(c, acquiring, patch, stamp, info);
  region_motion_.Remember(gray, BoxFromLandmarks(c.landmarks));
}

void FaceTracker::Track(const cv::Mat& gray, const cv::Rect& full, Time stamp,
                        const OrientationTimeline* timeline, const RowTiming* timing,
                        bool rot_ok, FaceInfo* info) {
  // The locked (or recently lost) face where the gyro predicts it:
  // re-detection near it when due, else the landmarks fitted there.
  Candidate c;
  cv::Mat patch;
  bool ok = false;
  std::vector<Eigen::Vector2d> predicted;
  PredictLandmarks(stamp, timeline, timing, &predicted);
  const Eigen::Vector2d pc = Mean(predicted);
  const cv::Rect2d pbox = BoxFromLandmarks(predicted);
  const cv::Rect2d inside = pbox & cv::Rect2d(0, 0, gray.cols, gray.rows);
  const bool in_frame = inside.area() > 0.5 * pbox.area();
  const double g = options_.redetect_region_scale;
  const cv::Rect2d big(pbox.x - 0.5 * (g - 1) * pbox.width,
                       pbox.y - 0.5 * (g - 1) * pbox.height, g * pbox.width,
                       g * pbox.height);
  const cv::Rect roi = cv::Rect(big) & full;
  // A followed head (Follow) is re-detected on every kFollowRedetectFrames-th
  // frame only: its landmarks are still fitted in its box every frame, and
  // the detector rarely finds a face turned that far.
  const bool may_detect = !following_ || frames_since_detect_ + 1 >= kFollowRedetectFrames;
  const bool want_detect = may_detect && (force_detect_ || state_ == TrackingState::kLost ||
                                          frames_since_detect_ + 1 >= options_.redetect_every_frames);
  bool tried_detect = false;
  if (want_detect && roi.area() > 0) {
    tried_detect = true;
    info->detected = true;
    double det_ms = 0.0;
    const auto t1 = Clock::now();
    if (DetectAndFit(gray, roi, &pbox, &c, &det_ms)) {
      ok = Evaluate(&gray, c, false, &pc, info, &patch);
    }
    info->timings.detect_ms += det_ms;
    info->timings.landmarks_ms += MsSince(t1) - det_ms;
  }
  // The landmarks fitted where the gyro says the face is: while tracking,
  // and while recently lost (the lost face is followed with the gyro), so
  // a face that blur hides from the detector is kept or taken back as
  // soon as its landmarks pass the checks against the locked face.
  if (!ok && state_ != TrackingState::kSearching && in_frame) {
    c = Candidate();
    c.box = pbox;
    const auto t1 = Clock::now();
    const bool fit = Fit(gray, c.box, &c.landmarks);
    info->timings.landmarks_ms += MsSince(t1);
    ok = fit && Evaluate(&gray, c, false, &pc, info, &patch);
    // Always re-detect after a failure.
    if (!ok && !tried_detect && may_detect && roi.area() > 0) {
      const FaceFailure first = info->failure;
      info->detected = true;
      double det_ms = 0.0;
      Candidate d;
      if (DetectAndFit(gray, roi, &pbox, &d, &det_ms)) {
        c = d;
        ok = Evaluate(&gray, c, false, &pc, info, &patch);
      }
      info->timings.detect_ms += det_ms;
      if (!ok) info->failure = first;
    }
  } else if (!ok && !in_frame && info->failure == FaceFailure::kNone) {
    info->failure = FaceFailure::kOutOfFrame;
  }
  if (ok && !RefitAgreesWithTurn(c)) {
    ok = false;
    info->failure = FaceFailure::kTurnMismatch;
  }
  if (ok) {
    TakeFit(gray, c, false, patch, &pc, stamp, info);
    return;
  }
  MarkFailure(info->failure == FaceFailure::kNone ? FaceFailure::kNoFace : info->failure,
              stamp, info);
  if (Follow(gray, stamp, pc, timeline, timing, info)) return;
  region_motion_.Clear();
  // Keep following the lost face with the gyro, so re-detection looks
  // where it should be.
  if (rot_ok) last_landmarks_ = predicted;
}

bool FaceTracker::Pose(const std::vector<Eigen::Vector2d>& landmarks, double* yaw, double* pitch,
                       double* roll) const {
  std::vector<Eigen::Vector2d> ideal = landmarks;
  const CameraIntrinsics& k = model_.intrinsics();
  if (k.HasDistortion()) {
    for (auto& p : ideal) UndistortPixel(k, p, &p);
  }
  CameraIntrinsics pinhole = k;
  pinhole.distortion = DistortionModel::kNone;
  return EstimateHeadPose(head_model_, ideal, pinhole, yaw, pitch, roll);
}

Status FaceTracker::ProcessExternal(const std::vector<Eigen::Vector2d>& lm,
                                    double external_confidence, Time stamp,
                                    const OrientationTimeline* timeline,
                                    const RowTiming* timing, FaceInfo* info) {
  const auto t_start = Clock::now();
  *info = FaceInfo();
  info->state = state_;
  if (!lm.empty() && (lm.size() != landmarks68::kCount || !AllFinite(lm))) {
    MarkFailure(FaceFailure::kBadInput, stamp, info);
    return Status::Error("face: external landmarks must be 68 finite points, got " +
                         std::to_string(lm.size()));
  }
  if (state_ == TrackingState::kLost &&
      ToSeconds(stamp - last_located_) > options_.lost_timeout_s) {
    Reset();
  }
  bool rot_ok = false;
  const Eigen::Quaterniond R_now = MidRotation(stamp, timeline, timing, &rot_ok);
  if (lm.empty()) {
    MarkFailure(FaceFailure::kNoFace, stamp, info);
  } else {
    Candidate c;
    c.landmarks = lm;
    c.box = BoxFromLandmarks(lm);
    const bool acquiring = state_ == TrackingState::kSearching;
    std::vector<Eigen::Vector2d> predicted;
    Eigen::Vector2d pc;
    if (!acquiring) {
      PredictLandmarks(stamp, timeline, timing, &predicted);
      pc = Mean(predicted);
    }
    cv::Mat patch;
    if (Evaluate(nullptr, c, acquiring, acquiring ? nullptr : &pc, info, &patch)) {
      Accept(c, acquiring, patch, stamp, info);
      info->confidence *= std::min(1.0, std::max(0.0, external_confidence));
    } else {
      MarkFailure(info->failure, stamp, info);
    }
  }
  if (rot_ok && !last_landmarks_.empty()) {
    last_rotation_ = R_now;
    have_last_rotation_ = true;
  }
  info->timings.total_ms = MsSince(t_start);
  return Status::Ok();
}

}  // namespace steadiface

#include "steadiface_core/face/face_tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "steadiface_core/camera/lens_distortion.h"
#include "steadiface_core/common/grey.h"
#include "steadiface_core/face/head_pose.h"
#include "steadiface_core/face/landmarks68.h"
#include "steadiface_core/face/upsampled_fit.h"

namespace steadiface {
namespace {

using Clock = std::chrono::steady_clock;
double MsSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

Eigen::Vector2d Mean(const std::vector<Eigen::Vector2d>& p) {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const auto& q : p) c += q;
  return c / static_cast<double>(std::max<size_t>(1, p.size()));
}

double RmsRadius(const std::vector<Eigen::Vector2d>& p, const Eigen::Vector2d& c) {
  double s = 0.0;
  for (const auto& q : p) s += (q - c).squaredNorm();
  return std::sqrt(s / std::max<size_t>(1, p.size()));
}

// Centred, unit-RMS shape.
std::vector<Eigen::Vector2d> Normalize(const std::vector<Eigen::Vector2d>& p) {
  const Eigen::Vector2d c = Mean(p);
  const double s = std::max(RmsRadius(p, c), 1e-9);
  std::vector<Eigen::Vector2d> out;
  out.reserve(p.size());
  for (const auto& q : p) out.push_back((q - c) / s);
  return out;
}

// RMS residual after the best rotation of normalized shape a onto b.
double ProcrustesResidual(const std::vector<Eigen::Vector2d>& a,
                          const std::vector<Eigen::Vector2d>& b) {
  double dot = 0.0, cross = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    dot += a[i].dot(b[i]);
    cross += a[i].x() * b[i].y() - a[i].y() * b[i].x();
  }
  const double th = std::atan2(cross, dot);
  const Eigen::Rotation2Dd R(th);
  double s = 0.0;
  for (size_t i = 0; i < a.size(); ++i) s += (R * a[i] - b[i]).squaredNorm();
  return std::sqrt(s / std::max<size_t>(1, a.size()));
}

cv::Rect2d Extent(const std::vector<Eigen::Vector2d>& p) {
  double x0 = 1e18, y0 = 1e18, x1 = -1e18, y1 = -1e18;
  for (const auto& q : p) {
    x0 = std::min(x0, q.x());
    y0 = std::min(y0, q.y());
    x1 = std::max(x1, q.x());
    y1 = std::max(y1, q.y());
  }
  return cv::Rect2d(x0, y0, x1 - x0, y1 - y0);
}

bool AllFinite(const std::vector<Eigen::Vector2d>& p) {
  for (const auto& q : p) {
    if (!q.allFinite()) return false;
  }
  return true;
}

}  // namespace

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
  } else if (!(o.appearance_update_rate >= 0.0 && o.appearance_update_rate <= 1.0)) {
    err << "face.appearance_update_rate must be in [0, 1], got "
        << o.appearance_update_rate;
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

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
  have_last_rotation_ = false;
  frames_since_detect_ = 0;
  frames_tracked_ = 0;
  force_detect_ = true;
}

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
    const Eigen::Vector2d n = model_.PixelToNormalized(p);
    Eigen::Vector2d w, m;
    if (model_.Project(n, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero(),
                       last_rotation_, &w) &&
        model_.Unproject(w, Eigen::Quaterniond::Identity(), Eigen::Vector2d::Zero(),
                         R_now, &m)) {
      p = model_.NormalizedToPixel(m);
    }
  }
  return true;
}

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
  const CameraIntrinsics& k = model_.intrinsics();
  for (size_t i = 0; i < lm.size(); ++i) {
    Eigen::Vector2d ideal = lm[i];
    if (k.HasDistortion()) UndistortPixel(k, lm[i], &ideal);
    info->landmarks_normalized[i] = model_.PixelToNormalized(ideal);
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

void FaceTracker::Accept(const Candidate& c, bool acquiring, const cv::Mat& patch,
                         Time stamp, FaceInfo* info) {
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
  last_seen_ = stamp;
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
    std::vector<Eigen::Vector2d> ideal = c.landmarks;
    const CameraIntrinsics& k = model_.intrinsics();
    if (k.HasDistortion()) {
      for (auto& p : ideal) UndistortPixel(k, p, &p);
    }
    CameraIntrinsics pinhole = k;
    pinhole.distortion = DistortionModel::kNone;
    info->has_pose = EstimateHeadPose(head_model_, ideal, pinhole, &info->yaw, &info->pitch, &info->roll);
    info->timings.pose_ms = MsSince(t0);
  }
}

void FaceTracker::MarkFailure(FaceFailure f, Time stamp, FaceInfo* info) {
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
      ToSeconds(stamp - last_seen_) > options_.lost_timeout_s) {
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
    Accept(c, true, patch, stamp, info);
  } else {
    MarkFailure(faces.empty() ? FaceFailure::kNoFace : info->failure, stamp, info);
  }
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
  const bool want_detect = force_detect_ || state_ == TrackingState::kLost ||
                           frames_since_detect_ + 1 >= options_.redetect_every_frames;
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
    if (!ok && !tried_detect && roi.area() > 0) {
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
  if (ok) {
    Accept(c, false, patch, stamp, info);
  } else {
    MarkFailure(info->failure == FaceFailure::kNone ? FaceFailure::kNoFace : info->failure,
                stamp, info);
    // Keep following the lost face with the gyro, so re-detection looks
    // where it should be.
    if (rot_ok) last_landmarks_ = predicted;
  }
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
      ToSeconds(stamp - last_seen_) > options_.lost_timeout_s) {
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

#include "steadiface_core/visual/visual_rotation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <utility>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "steadiface_core/common/stopwatch.h"
#include "visual/rotation_fit.h"

namespace steadiface {

Status ValidateVisualRotationOptions(const VisualRotationOptions& o) {
  std::ostringstream err;
  if (o.max_side_px < 64 || o.max_side_px > 8192) {
    err << "visual.max_side_px must be in [64, 8192], got " << o.max_side_px;
  } else if (o.max_features < 8 || o.max_features > 5000) {
    err << "visual.max_features must be in [8, 5000], got " << o.max_features;
  } else if (!(o.min_distance_px >= 1.0 && o.min_distance_px <= 200.0)) {
    err << "visual.min_distance_px must be in [1, 200], got "
        << o.min_distance_px;
  } else if (o.klt_window_px < 5 || o.klt_window_px > 101 ||
             o.klt_window_px % 2 == 0) {
    err << "visual.klt_window_px must be odd, in [5, 101], got "
        << o.klt_window_px;
  } else if (!(o.min_texture > 0.0 && o.min_texture <= 1.0)) {
    err << "visual.min_texture must be in (0, 1], got " << o.min_texture;
  } else if (o.klt_levels < 0 || o.klt_levels > 8) {
    err << "visual.klt_levels must be in [0, 8], got " << o.klt_levels;
  } else if (!(o.inlier_threshold_px > 0.0 && o.inlier_threshold_px <= 50.0)) {
    err << "visual.inlier_threshold_px must be in (0, 50], got "
        << o.inlier_threshold_px;
  } else if (o.ransac_iterations < 1 || o.ransac_iterations > 10000) {
    err << "visual.ransac_iterations must be in [1, 10000], got "
        << o.ransac_iterations;
  } else if (o.min_inliers_precise < 3 ||
             o.min_inliers_precise > o.min_inliers ||
             o.min_inliers > o.max_features) {
    err << "visual: need 3 <= min_inliers_precise <= min_inliers <= "
           "max_features, got "
        << o.min_inliers_precise << " / " << o.min_inliers;
  } else if (!(o.max_turn_error_px > 0.0 && o.max_turn_error_px <= 100.0)) {
    err << "visual.max_turn_error_px must be in (0, 100], got "
        << o.max_turn_error_px;
  } else if (!(o.min_inlier_ratio >= 0.0 && o.min_inlier_ratio <= 1.0)) {
    err << "visual.min_inlier_ratio must be in [0, 1], got "
        << o.min_inlier_ratio;
  } else if (!(o.feature_noise_px > 0.0 && o.feature_noise_px <= 20.0) ||
             !(o.alpha_prior_rad_s2 > 0.0 && o.alpha_prior_rad_s2 <= 1e4) ||
             !(o.beta_prior_rad_s3 > 0.0 && o.beta_prior_rad_s3 <= 1e6)) {
    err << "visual.feature_noise_px must be in (0, 20], alpha_prior_rad_s2 "
           "in (0, 1e4] and beta_prior_rad_s3 in (0, 1e6]";
  } else if (!(o.face_margin >= 0.0 && o.face_margin <= 10.0) ||
             !(o.body_width >= 0.0 && o.body_width <= 20.0)) {
    err << "visual.face_margin must be in [0, 10] and body_width in [0, 20]";
  } else if (o.trail_frames < 0 || o.trail_frames > visual::SceneTrail::kMaxFrames ||
             !(o.trail_threshold_px > 0.0 && o.trail_threshold_px <= 100.0)) {
    err << "visual.trail_frames must be in [0, " << visual::SceneTrail::kMaxFrames
        << "] and trail_threshold_px in (0, 100], got " << o.trail_frames << " / "
        << o.trail_threshold_px;
  } else if (!(o.stray_hold_s >= 0.0 && o.stray_hold_s <= 10.0) ||
             !(o.stray_radius_px >= 0.0 && o.stray_radius_px <= 640.0) ||
             o.stray_min_count < 1 || o.stray_min_count > 100) {
    err << "visual.stray_hold_s must be in [0, 10], stray_radius_px in [0, 640] and "
           "stray_min_count in [1, 100], got "
        << o.stray_hold_s << " / " << o.stray_radius_px << " / " << o.stray_min_count;
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

Status VisualRotationEstimator::Create(
    const CameraModel& model, const RowTiming& timing,
    const VisualRotationOptions& options,
    std::unique_ptr<VisualRotationEstimator>* out) {
  Status s = ValidateVisualRotationOptions(options);
  if (!s.ok()) return s;
  if (timing.height() != model.intrinsics().height) {
    return Status::Error(
        "visual rotation: row timing is for another image height");
  }
  out->reset(new VisualRotationEstimator(model, timing, options));
  return Status::Ok();
}

VisualRotationEstimator::VisualRotationEstimator(
    const CameraModel& model, const RowTiming& timing,
    const VisualRotationOptions& options)
    : model_(model), timing_(timing), options_(options) {
  const CameraIntrinsics& k = model.intrinsics();
  const int longest = std::max(k.width, k.height);
  scale_ = longest > options.max_side_px
               ? static_cast<double>(options.max_side_px) / longest
               : 1.0;
}

void VisualRotationEstimator::Reset() {
  prev_.release();
  prev_pyramid_.clear();
  tracks_.Clear();
  strays_.clear();
}

cv::Mat VisualRotationEstimator::SubjectMask(const cv::Size& size,
                                             const cv::Rect2d& face) const {
  // 255 where features may be taken (the copy's pixels).
  cv::Mat mask(size, CV_8UC1, cv::Scalar(255));
  if (face.width <= 0.0 || face.height <= 0.0) return mask;
  const double m = options_.face_margin * face.width;
  const cv::Rect2d head(face.x - m, face.y - m, face.width + 2 * m,
                        face.height + m);
  const double bw = options_.body_width * face.width;
  const double cx = face.x + 0.5 * face.width;
  const cv::Rect2d body(cx - 0.5 * bw, face.br().y, bw, 1e6);
  for (const cv::Rect2d& r : {head, body}) {
    const cv::Rect s(
        cv::Point(static_cast<int>(std::floor(r.x * scale_)),
                  static_cast<int>(std::floor(r.y * scale_))),
        cv::Point(
            static_cast<int>(std::ceil(r.br().x * scale_)),
            static_cast<int>(std::ceil(std::min(r.br().y, 1e5) * scale_))));
    const cv::Rect clipped = s & cv::Rect(0, 0, size.width, size.height);
    if (clipped.area() > 0) mask(clipped).setTo(0);
  }
  return mask;
}

void VisualRotationEstimator::Refill(const cv::Mat& small,
                                     const cv::Mat& mask) {
  if (static_cast<int>(tracks_.size()) >= options_.max_features / 2)
    return;
  cv::Mat free = mask.clone();
  const int r = static_cast<int>(std::ceil(options_.min_distance_px));
  for (const cv::Point2f& p : tracks_.points)
    cv::circle(free, p, r, cv::Scalar(0), -1);
  BlockStrays(&free);
  std::vector<cv::Point2f> fresh;
  const int want =
      options_.max_features - static_cast<int>(tracks_.size());
  cv::goodFeaturesToTrack(small, fresh, want, 0.01, options_.min_distance_px,
                          free, 5);
  for (const cv::Point2f& p : fresh) tracks_.Add(p, 0, visual::SceneTrail());
}

void VisualRotationEstimator::Tracks::Clear() {
  points.clear();
  age.clear();
  trail.clear();
}

void VisualRotationEstimator::Tracks::Add(const cv::Point2f& p, int a,
                                          const visual::SceneTrail& t) {
  points.push_back(p);
  age.push_back(a);
  trail.push_back(t);
}

namespace {

// A copy pixel to the camera ray (X/Z, Y/Z) through it.
Eigen::Vector2d Ray(const CameraModel& model, double scale,
                    const cv::Point2f& p) {
  const Eigen::Vector2d px((p.x + 0.5) / scale - 0.5, (p.y + 0.5) / scale - 0.5);
  Eigen::Vector2d n;
  model.RawPixelToNormalized(px, &n);
  return (n - Eigen::Vector2d(0.5, 0.5)) / model.real_focal();
}

}  // namespace

void VisualRotationEstimator::Track(const cv::Mat& small, const cv::Mat& mask,
                                    Time stamp, VisualRotation* out) {
  std::vector<cv::Point2f> next;
  std::vector<unsigned char> status;
  std::vector<float> error;
  const int w = options_.klt_window_px;
  // The pyramids (with their derivatives) are built once per frame: this
  // frame's is the next one's previous.
  if (prev_pyramid_.empty()) {
    cv::buildOpticalFlowPyramid(prev_, prev_pyramid_, cv::Size(w, w), options_.klt_levels);
  }
  std::vector<cv::Mat> pyramid;
  cv::buildOpticalFlowPyramid(small, pyramid, cv::Size(w, w), options_.klt_levels);
  cv::calcOpticalFlowPyrLK(
      prev_pyramid_, pyramid, tracks_.points, next, status, error, cv::Size(w, w),
      options_.klt_levels,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30,
                       0.01),
      0, options_.min_texture);
  std::vector<visual::BearingPair> pairs;
  Tracks kept;
  std::vector<double> weights;
  const cv::Rect2f inside(0.f, 0.f, small.cols - 1.f, small.rows - 1.f);
  for (size_t i = 0; i < next.size(); ++i) {
    if (!status[i] || !inside.contains(next[i]) ||
        mask.at<unsigned char>(cvRound(next[i].y), cvRound(next[i].x)) == 0) {
      continue;
    }
    visual::BearingPair p;
    const Eigen::Vector2d r1 = Ray(model_, scale_, tracks_.points[i]);
    p.b1 = Eigen::Vector3d(r1.x(), r1.y(), 1.0);
    p.n2 = Ray(model_, scale_, next[i]);
    const double y1 = (tracks_.points[i].y + 0.5) / scale_ - 0.5;
    const double y2 = (next[i].y + 0.5) / scale_ - 0.5;
    const double t1 = ToSeconds(timing_.RowTime(prev_stamp_, y1) - out->stamp);
    const double t2 = ToSeconds(timing_.RowTime(stamp, y2) - out->stamp);
    p.c = t2 - t1;
    p.d = 0.5 * (t2 * t2 - t1 * t1);
    p.e = (t2 * t2 * t2 - t1 * t1 * t1) / 6.0;
    pairs.push_back(p);
    kept.Add(next[i], tracks_.age[i], tracks_.trail[i]);
    // A feature that has moved with the scene for a few frames outvotes a
    // fresh one: the scene it lies on has shown itself to be the scene.
    weights.push_back(1.0 + std::min(tracks_.age[i], kMatureAge));
  }
  out->tracked = static_cast<int>(pairs.size());
  std::vector<cv::Point2f> strays;
  Fit(pairs, weights, stamp, out, &kept, &strays);
  RememberStrays(strays, stamp);
  std::swap(tracks_, kept);
  prev_pyramid_.swap(pyramid);
}

void VisualRotationEstimator::Fit(const std::vector<visual::BearingPair>& pairs,
                                  const std::vector<double>& weights, Time stamp,
                                  VisualRotation* out, Tracks* kept,
                                  std::vector<cv::Point2f>* strays) const {
  visual::RotationFit fit;
  const double focal_px = model_.real_focal() * model_.intrinsics().width;
  const double sigma_n = options_.feature_noise_px / focal_px;
  visual::MotionPrior prior;
  prior.alpha = sigma_n * sigma_n / (options_.alpha_prior_rad_s2 * options_.alpha_prior_rad_s2);
  prior.beta = sigma_n * sigma_n / (options_.beta_prior_rad_s3 * options_.beta_prior_rad_s3);
  if (!visual::FitMotion(pairs, weights, focal_px, options_.inlier_threshold_px,
                         options_.ransac_iterations, prior,
                         static_cast<uint64_t>(ToNanoseconds(stamp)), &fit)) {
    return;
  }
  out->inliers = static_cast<int>(fit.inliers.size());
  out->residual_px = fit.rms_px;
  out->support = fit.support;
  out->turn_error_px = fit.turn_sigma_px;
  // Many inliers are trusted; a few only when they pin the turn down
  // (VisualRotationOptions::min_inliers_precise).
  const bool enough = out->inliers >= options_.min_inliers ||
                      (out->inliers >= options_.min_inliers_precise &&
                       fit.turn_sigma_px <= options_.max_turn_error_px);
  out->valid = enough && fit.support >= options_.min_inlier_ratio;
  if (!out->valid) {  // not trusted: every track is kept as it was
    for (visual::SceneTrail& t : kept->trail) t.Clear();
    return;
  }
  out->omega = fit.motion.head<3>();
  out->alpha = fit.motion.segment<3>(3);
  out->beta = fit.motion.tail<3>();
  // Keep tracking the features that moved with the camera, one frame
  // older: a passer-by's are dropped, and fresh ones are found where the
  // scene is.
  Tracks in;
  for (int i : fit.inliers) {
    visual::SceneTrail trail = kept->trail[i];
    if (options_.trail_frames > 0) {
      const visual::BearingPair& p = pairs[i];
      const double strayed =
          trail.Advance(visual::PairTurn(fit.motion, p), p.b1, p.n2, options_.trail_frames) *
          focal_px;
      if (!(strayed <= options_.trail_threshold_px)) {
        strays->push_back(kept->points[i]);
        continue;
      }
    }
    in.Add(kept->points[i], kept->age[i] + 1, trail);
  }
  std::swap(*kept, in);
}

void VisualRotationEstimator::BlockStrays(cv::Mat* free) const {
  // A near object strays as a group; a lone stray is the noise of one
  // track, and the scene around it is kept.
  const int rs = static_cast<int>(std::ceil(options_.stray_radius_px));
  const float r2 = static_cast<float>(options_.stray_radius_px * options_.stray_radius_px);
  for (const auto& p : strays_) {
    int near = 0;
    for (const auto& q : strays_) {
      const cv::Point2f d = p.first - q.first;
      if (d.dot(d) <= r2) ++near;
    }
    if (near >= options_.stray_min_count) cv::circle(*free, p.first, rs, cv::Scalar(0), -1);
  }
}

void VisualRotationEstimator::RememberStrays(const std::vector<cv::Point2f>& strays,
                                             Time stamp) {
  if (!(options_.stray_hold_s > 0.0)) return;
  for (const cv::Point2f& p : strays) strays_.emplace_back(p, stamp);
  const Time oldest = stamp - FromSeconds(options_.stray_hold_s);
  strays_.erase(std::remove_if(strays_.begin(), strays_.end(),
                               [oldest](const std::pair<cv::Point2f, Time>& s) {
                                 return s.second < oldest;
                               }),
                strays_.end());
  // Bounded: a few frames' worth of every feature straying at once.
  if (strays_.size() > kMaxStrays) strays_.erase(strays_.begin(), strays_.end() - kMaxStrays);
}

Status VisualRotationEstimator::Process(const cv::Mat& gray, Time stamp,
                                        const cv::Rect2d& face,
                                        VisualRotation* out) {
  const auto t0 = std::chrono::steady_clock::now();
  *out = VisualRotation();
  out->stamp = stamp;
  Status s = CheckGray(gray);
  if (!s.ok()) return s;
  const CameraIntrinsics& k = model_.intrinsics();
  if (!prev_.empty() && stamp <= prev_stamp_)
    Reset();  // time went back: start over
  const cv::Mat small = Copy(gray);
  const cv::Mat mask = SubjectMask(small.size(), face);
  // After Remember() the previous frame has a picture but no features yet.
  if (!prev_.empty() && tracks_.empty()) Refill(prev_, mask);
  const bool track = !prev_.empty() && !tracks_.empty();
  if (track) {
    const double mid = 0.5 * (k.height - 1);
    out->stamp =
        timing_.RowTime(prev_stamp_, mid) +
        (timing_.RowTime(stamp, mid) - timing_.RowTime(prev_stamp_, mid)) / 2;
    Track(small, mask, stamp, out);  // leaves this frame's pyramid
  } else {
    prev_pyramid_.clear();
  }
  Refill(small, mask);
  prev_ = small;
  prev_stamp_ = stamp;
  out->ms = MsSince(t0);
  return Status::Ok();
}

cv::Mat VisualRotationEstimator::Copy(const cv::Mat& gray) const {
  cv::Mat small;
  if (scale_ < 1.0) {
    cv::resize(gray, small, cv::Size(), scale_, scale_, cv::INTER_AREA);
  } else {
    small = gray.clone();
  }
  return small;
}

Status VisualRotationEstimator::CheckGray(const cv::Mat& gray) const {
  const CameraIntrinsics& k = model_.intrinsics();
  if (gray.empty() || gray.type() != CV_8UC1 || gray.cols != k.width || gray.rows != k.height) {
    return Status::Error("visual rotation: need an 8-bit grey " + std::to_string(k.width) + "x" +
                         std::to_string(k.height) + " image");
  }
  return Status::Ok();
}

Status VisualRotationEstimator::Remember(const cv::Mat& gray, Time stamp) {
  Status s = CheckGray(gray);
  if (!s.ok()) return s;
  prev_ = Copy(gray);
  prev_pyramid_.clear();
  prev_stamp_ = stamp;
  tracks_.Clear();
  strays_.clear();  // where they were is out of date
  return Status::Ok();
}

}  // namespace steadiface

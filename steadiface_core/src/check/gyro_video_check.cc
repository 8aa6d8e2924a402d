#include "steadiface_core/check/gyro_video_check.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "steadiface_core/camera/lens_distortion.h"
#include "steadiface_core/common/grey.h"

namespace steadiface {
namespace {

constexpr int kBands = 5;

double Median(std::vector<double>* v) {
  if (v->empty()) return NAN;
  const size_t m = v->size() / 2;
  std::nth_element(v->begin(), v->begin() + m, v->end());
  return (*v)[m];
}

}  // namespace

Status ValidateGyroVideoCheckOptions(const GyroVideoCheckOptions& o) {
  if (!(o.stride >= 1 && o.stride <= 100)) {
    return Status::Error("gyro_video_check/stride must be in [1, 100]");
  }
  if (!(o.track_width >= 64 && o.track_width <= 4096)) {
    return Status::Error(
        "gyro_video_check/track_width must be in [64, 4096] px");
  }
  if (!(o.max_features >= 8 && o.max_features <= 2000)) {
    return Status::Error("gyro_video_check/max_features must be in [8, 2000]");
  }
  if (!(o.max_fb_error_px > 0.0 && o.max_fb_error_px <= 10.0)) {
    return Status::Error("gyro_video_check/max_fb_error must be in (0, 10] px");
  }
  if (!(o.window_s >= 0.5 && o.window_s <= 60.0)) {
    return Status::Error("gyro_video_check/window must be in [0.5, 60] s");
  }
  if (!(o.offset_range_s >= 0.0 && o.offset_range_s <= 0.5) ||
      !(o.offset_step_s >= 0.0005 && o.offset_step_s <= 0.1)) {
    return Status::Error(
        "gyro_video_check/offset_range must be in [0, 0.5] s and offset_step "
        "in [0.0005, 0.1] s");
  }
  if (!(o.min_pairs >= 2) || !(o.min_motion_px >= 0.0) ||
      !(o.better_mounting_ratio > 0.0 && o.better_mounting_ratio < 1.0) ||
      !(o.offset_warn_s > 0.0)) {
    return Status::Error(
        "gyro_video_check: min_pairs >= 2, min_motion >= 0, "
        "better_mounting_ratio in (0, 1), "
        "offset_warn > 0");
  }
  if (!(o.apply_rate_s_per_s > 0.0 && o.apply_rate_s_per_s <= 1.0)) {
    return Status::Error("gyro_video_check/apply_rate must be in (0, 1] s/s");
  }
  return Status::Ok();
}

const std::vector<Eigen::Quaterniond>&
GyroVideoCheck::SignedAxisPermutations() {
  static const std::vector<Eigen::Quaterniond> all = [] {
    std::vector<Eigen::Quaterniond> v;
    const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                             {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
    for (const auto& p : perms) {
      for (int signs = 0; signs < 8; ++signs) {
        Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
        for (int r = 0; r < 3; ++r) M(r, p[r]) = (signs >> r) & 1 ? -1.0 : 1.0;
        if (M.determinant() > 0) v.emplace_back(M);
      }
    }
    return v;
  }();
  return all;
}

Status GyroVideoCheck::Create(const CameraIntrinsics& intrinsics,
                              const RowTiming& timing,
                              const Eigen::Quaterniond& R_cam_imu,
                              const GyroVideoCheckOptions& options,
                              std::unique_ptr<GyroVideoCheck>* out) {
  Status s = ValidateIntrinsics(intrinsics);
  if (!s.ok()) return s;
  s = ValidateGyroVideoCheckOptions(options);
  if (!s.ok()) return s;
  if (!R_cam_imu.coeffs().allFinite() ||
      std::abs(R_cam_imu.norm() - 1.0) > 1e-6) {
    return Status::Error(
        "gyro_video_check: R_cam_imu must be a unit quaternion");
  }
  out->reset(new GyroVideoCheck(intrinsics, timing, R_cam_imu, options));
  return Status::Ok();
}

GyroVideoCheck::GyroVideoCheck(const CameraIntrinsics& intrinsics,
                               const RowTiming& timing,
                               const Eigen::Quaterniond& R_cam_imu,
                               const GyroVideoCheckOptions& options)
    : k_(intrinsics),
      timing_(timing),
      R_cam_imu_(R_cam_imu.normalized()),
      options_(options) {
  scale_ = std::min(1.0, static_cast<double>(options.track_width) / k_.width);
  const int n = static_cast<int>(
      std::floor(options.offset_range_s / options.offset_step_s + 1e-9));
  for (int i = -n; i <= n; ++i) offsets_.push_back(i * options.offset_step_s);
  // Each signed permutation P as a change of the configured mounting:
  // C = P R_cam_imu^-1 (a relative rotation under P is C rel C^T).
  for (const Eigen::Quaterniond& P : SignedAxisPermutations()) {
    mountings_.push_back(
        (P * R_cam_imu_.conjugate()).normalized().toRotationMatrix());
  }
}

void GyroVideoCheck::Reset() {
  has_prev_ = false;
  frame_index_ = 0;
  prev_grey_.release();
  window_.clear();
  pending_.clear();
  result_ = GyroVideoCheckResult();
}

void GyroVideoCheck::Process(const cv::Mat& image, Time stamp,
                             const OrientationTimeline& timeline,
                             const cv::Rect2d& face_box) {
  if (!options_.enabled || image.empty() || image.cols != k_.width ||
      image.rows != k_.height) {
    return;
  }
  if (has_prev_ && stamp <= prev_stamp_) Reset();
  // Pairs (i - 1, i) with i a multiple of the stride: only frames i - 1 and i
  // are converted.
  const uint64_t n = frame_index_++;
  const int stride = options_.stride;
  const bool first_of_pair = (n + 1) % stride == 0;
  const bool second_of_pair = n % stride == 0 && n > 0;
  if (!first_of_pair && !second_of_pair) {
    has_prev_ = false;
    EvaluateReady(timeline);
    return;
  }
  cv::Mat grey = ToGrey(image);
  if (scale_ < 1.0) {
    cv::resize(grey, grey, cv::Size(), scale_, scale_, cv::INTER_LINEAR);
  } else {
    grey = grey.clone();
  }
  if (!second_of_pair) has_prev_ = false;
  if (has_prev_) {
    // Features in the previous frame, outside the (enlarged) face.
    cv::Mat mask(prev_grey_.size(), CV_8UC1, cv::Scalar(255));
    if (face_box.width > 0 && face_box.height > 0) {
      const cv::Rect2d r(face_box.x - 0.3 * face_box.width,
                         face_box.y - 0.3 * face_box.height,
                         1.6 * face_box.width, 1.6 * face_box.height);
      cv::rectangle(
          mask,
          cv::Rect(cvRound(r.x * scale_), cvRound(r.y * scale_),
                   cvRound(r.width * scale_), cvRound(r.height * scale_)),
          cv::Scalar(0), cv::FILLED);
    }
    std::vector<cv::Point2f> a, b, back;
    cv::goodFeaturesToTrack(prev_grey_, a, options_.max_features, 0.01, 8.0,
                            mask);
    Pending p;
    p.a = prev_stamp_;
    p.b = stamp;
    if (a.size() >= 8) {
      std::vector<uchar> st1, st2;
      std::vector<float> e1, e2;
      cv::calcOpticalFlowPyrLK(prev_grey_, grey, a, b, st1, e1,
                               cv::Size(11, 11), 2);
      cv::calcOpticalFlowPyrLK(grey, prev_grey_, b, back, st2, e2,
                               cv::Size(11, 11), 2);
      for (size_t i = 0; i < a.size(); ++i) {
        if (!st1[i] || !st2[i]) continue;
        const double fb = std::hypot(back[i].x - a[i].x, back[i].y - a[i].y);
        if (!(fb <= options_.max_fb_error_px)) continue;
        Eigen::Vector2d pa, pb;
        if (!UndistortPixel(k_, Eigen::Vector2d(a[i].x, a[i].y) / scale_,
                            &pa) ||
            !UndistortPixel(k_, Eigen::Vector2d(b[i].x, b[i].y) / scale_,
                            &pb)) {
          continue;
        }
        p.ya.push_back(a[i].y / scale_);
        p.yb.push_back(b[i].y / scale_);
        p.xa.push_back(pa);
        p.xb.push_back(pb);
      }
    }
    if (p.xa.size() >= 8) pending_.push_back(std::move(p));
    while (pending_.size() > 8) pending_.pop_front();  // bounded
  }
  prev_grey_ = grey;
  prev_stamp_ = stamp;
  has_prev_ = first_of_pair;
  EvaluateReady(timeline);
}

void GyroVideoCheck::EvaluateReady(const OrientationTimeline& timeline) {
  // Evaluate the pairs the gyro now covers, offsets included.
  // Offsets are searched around the configured imu/time_offset: a live
  // correction the timeline applies (apply_offset) is undone here, so the
  // window's evidence does not depend on it.
  const Duration range = FromSeconds(options_.offset_range_s) +
                         FromSeconds(timeline.offset_correction());
  bool added = false;
  while (!pending_.empty() &&
         timeline.Covers(timing_.LastRowTime(pending_.front().b) + range)) {
    Evaluate(pending_.front(), timeline);
    pending_.pop_front();
    added = true;
  }
  if (added) Judge();
}

void GyroVideoCheck::Evaluate(const Pending& p,
                              const OrientationTimeline& timeline) {
  const Duration correction = FromSeconds(timeline.offset_correction());
  const Duration range = FromSeconds(options_.offset_range_s);
  if (!timeline.Covers(timing_.FirstRowTime(p.a) - range + correction)) return;
  // Rotations at each row band's centre, per offset hypothesis.
  auto band = [&](double y) {
    return std::min(kBands - 1,
                    std::max(0, static_cast<int>(y * kBands / k_.height)));
  };
  auto rotations = [&](Time stamp, double offset,
                       std::array<Eigen::Quaterniond, kBands>* R) {
    for (int i = 0; i < kBands; ++i) {
      const double yc = (i + 0.5) * k_.height / kBands;
      if (!QuerySucceeded(timeline.RealRotation(
              timing_.RowTime(stamp, yc) + FromSeconds(offset) + correction,
              &(*R)[i]))) {
        return false;
      }
    }
    return true;
  };
  PairRecord rec;
  rec.stamp = p.b;
  std::vector<double> r;
  r.reserve(p.xa.size());
  for (size_t i = 0; i < p.xa.size(); ++i)
    r.push_back((p.xb[i] - p.xa[i]).norm());
  rec.motion_px = Median(&r);
  // Each track's ray in frame a, and its rows' bands.
  const size_t n = p.xa.size();
  std::vector<Eigen::Vector3d> ray(n);
  for (size_t i = 0; i < n; ++i) {
    ray[i] = Eigen::Vector3d((p.xa[i].x() - k_.cx) / k_.fx,
                             (p.xa[i].y() - k_.cy) / k_.fy, 1.0);
  }
  // Median pixel residual of the tracks when each ray moves by rel[i]
  // conjugated by C (an alternative mounting: C rel C^T).
  auto residual = [&](const std::vector<Eigen::Matrix3d>& rel,
                      const Eigen::Matrix3d* C) {
    r.clear();
    for (size_t i = 0; i < n; ++i) {
      const Eigen::Vector3d q =
          C != nullptr
              ? Eigen::Vector3d(*C * (rel[i] * (C->transpose() * ray[i])))
              : Eigen::Vector3d(rel[i] * ray[i]);
      if (!(q.z() > 1e-6)) {
        r.push_back(1e3);
        continue;
      }
      const Eigen::Vector2d pred(k_.fx * q.x() / q.z() + k_.cx,
                                 k_.fy * q.y() / q.z() + k_.cy);
      r.push_back((pred - p.xb[i]).norm());
    }
    return Median(&r);
  };
  rec.grid.resize(mountings_.size() * offsets_.size());
  std::array<Eigen::Quaterniond, kBands> Ra, Rb;
  std::vector<Eigen::Matrix3d> rel(n);
  for (size_t o = 0; o < offsets_.size(); ++o) {
    if (!rotations(p.a, offsets_[o], &Ra) ||
        !rotations(p.b, offsets_[o], &Rb)) {
      return;
    }
    for (size_t i = 0; i < n; ++i) {
      rel[i] = (Rb[band(p.yb[i])] * Ra[band(p.ya[i])].conjugate())
                   .toRotationMatrix();
    }
    rec.offset_residual.push_back(residual(rel, nullptr));
    for (size_t m = 0; m < mountings_.size(); ++m) {
      rec.grid[m * offsets_.size() + o] = residual(rel, &mountings_[m]);
    }
  }
  window_.push_back(std::move(rec));
}

void GyroVideoCheck::Judge() {
  const Time newest = window_.empty() ? Time() : window_.back().stamp;
  while (!window_.empty() &&
         window_.front().stamp < newest - FromSeconds(options_.window_s)) {
    window_.pop_front();
  }
  GyroVideoCheckResult res;
  res.pairs = static_cast<int>(window_.size());
  if (window_.empty()) {
    result_ = res;
    return;
  }
  const size_t n_off = offsets_.size(),
               n_mount = SignedAxisPermutations().size();
  std::vector<double> off(n_off, 0.0), grid(n_off * n_mount, 0.0);
  for (const PairRecord& p : window_) {
    res.motion_px += p.motion_px;
    for (size_t i = 0; i < n_off; ++i) off[i] += p.offset_residual[i];
    for (size_t i = 0; i < grid.size(); ++i) grid[i] += p.grid[i];
  }
  const double n = static_cast<double>(window_.size());
  res.motion_px /= n;
  // The minimum of a residual curve over the offsets, refined by a parabola
  // through its neighbours: the offset hypothesis delta (the timeline read
  // at t + delta matches the video at t) and the curve's minimum.
  auto best_offset = [&](const double* curve, double* delta) {
    const size_t b = std::min_element(curve, curve + n_off) - curve;
    *delta = offsets_[b];
    if (b > 0 && b + 1 < n_off) {
      const double denom = curve[b - 1] - 2.0 * curve[b] + curve[b + 1];
      if (denom > 1e-12) {
        *delta += 0.5 * options_.offset_step_s * (curve[b - 1] - curve[b + 1]) /
                  denom;
      }
    }
    return curve[b];
  };
  // The configured mounting, at its best offset; every signed permutation
  // at its own best offset (so an offset error does not condemn the
  // rotation, nor a wrong rotation the offset).
  double configured_delta = 0.0;
  const double configured_min = best_offset(off.data(), &configured_delta) / n;
  res.residual_configured_px = configured_min;
  size_t best_m = 0;
  double best_min = std::numeric_limits<double>::infinity(), best_delta = 0.0;
  for (size_t m = 0; m < n_mount; ++m) {
    double d = 0.0;
    const double v = best_offset(&grid[m * n_off], &d) / n;
    if (v < best_min) {
      best_min = v;
      best_m = m;
      best_delta = d;
    }
  }
  res.residual_best_mounting_px = best_min;
  res.best_R_cam_imu = SignedAxisPermutations()[best_m];
  res.judged = res.pairs >= options_.min_pairs &&
               res.motion_px >= options_.min_motion_px;
  res.rotation_contradicts =
      res.judged && res.residual_best_mounting_px <
                        options_.better_mounting_ratio * configured_min;
  // The correction to add to imu/time_offset is the hypothesis' negative,
  // for the mounting that explains the video (the suggested one when the
  // configured rotation contradicts it).
  res.offset_correction_s =
      -(res.rotation_contradicts ? best_delta : configured_delta);
  res.offset_off = res.judged && !res.rotation_contradicts &&
                   std::abs(res.offset_correction_s) > options_.offset_warn_s;
  result_ = res;
}

}  // namespace steadiface

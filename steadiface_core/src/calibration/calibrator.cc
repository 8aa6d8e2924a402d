#include "steadiface_core/calibration/calibrator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "calibration/closed_form.h"
#include "calibration/refinement.h"
#include "steadiface_core/calibration/gyro_integral.h"
#include "steadiface_core/camera/lens_distortion.h"
#include "steadiface_core/check/gyro_video_check.h"
#include "steadiface_core/common/ceres_compat.h"
#include "steadiface_core/common/grey.h"
#include "steadiface_core/common/percentile.h"
#include "steadiface_core/common/so3.h"

namespace steadiface {

using namespace calibration_internal;  // NOLINT: the calibrator's own steps

Status ValidateCalibratorOptions(const CalibratorOptions& o) {
  std::ostringstream err;
  if (o.track_width < 64 || o.track_width > 8192) {
    err << "calibrate: track_width must be in [64, 8192] px";
  } else if (o.max_features < 8 || o.max_features > 5000) {
    err << "calibrate: max_features must be in [8, 5000]";
  } else if (!(o.coarse_range_s >= 0 && o.coarse_range_s <= 5) ||
             !(o.coarse_step_s > 0 && o.coarse_step_s <= 0.1)) {
    err << "calibrate: coarse_range_s must be in [0, 5] s and coarse_step_s in "
           "(0, 0.1] s";
  } else if (!(o.min_duration_s >= 0) || o.min_pairs < 2 || o.min_tracks < 3 ||
             !(o.min_angular_speed >= 0)) {
    err << "calibrate: min_duration_s >= 0, min_pairs >= 2, min_tracks >= 3 "
           "and "
           "min_angular_speed >= 0 required";
  } else if (!(o.max_offset_sigma_s > 0) || !(o.max_readout_sigma_s > 0) ||
             !(o.loss_scale_px > 0) || !(o.max_fb_error_px > 0)) {
    err << "calibrate: sigma limits, loss scale and FB error must be positive";
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

Calibrator::Calibrator(const CameraIntrinsics& k,
                       const RollingShutterOptions& shutter,
                       const Eigen::Quaterniond& R, double offset,
                       const CalibratorOptions& o)
    : k_(k),
      shutter_(shutter),
      initial_R_(R.normalized()),
      initial_offset_s_(offset),
      options_(o) {
  scale_ = std::min(1.0, static_cast<double>(o.track_width) / k.width);
}

Status Calibrator::Create(const CameraIntrinsics& intrinsics,
                          const RollingShutterOptions& shutter,
                          const Eigen::Quaterniond& R, double offset,
                          const CalibratorOptions& options,
                          std::unique_ptr<Calibrator>* out) {
  Status s = ValidateCalibratorOptions(options);
  if (!s.ok()) return s;
  s = ValidateIntrinsics(intrinsics);
  if (!s.ok()) return s;
  s = ValidateRollingShutterOptions(shutter);
  if (!s.ok()) return s;
  if (!std::isfinite(offset) || !R.coeffs().allFinite() || R.norm() < 0.5) {
    return Status::Error(
        "calibrate: initial offset and rotation must be finite");
  }
  out->reset(new Calibrator(intrinsics, shutter, R, offset, options));
  return Status::Ok();
}

void Calibrator::AddGyro(const GyroSample& s) {
  if (s.angular_velocity.allFinite()) gyro_.push_back(s);
}

Status Calibrator::AddFrame(const cv::Mat& image, Time stamp) {
  if (image.empty() || image.cols != k_.width || image.rows != k_.height ||
      image.depth() != CV_8U || image.channels() < 1 || image.channels() > 4) {
    return Status::Error("calibrate: frames must be 8-bit, 1-4 channels, " +
                         std::to_string(k_.width) + "x" +
                         std::to_string(k_.height));
  }
  if (frames_ > 0 && stamp <= prev_stamp_) {
    return Status::Error("calibrate: frame stamps must increase");
  }
  cv::Mat grey = ToGrey(image);
  if (scale_ < 1.0)
    cv::resize(grey, grey, cv::Size(), scale_, scale_, cv::INTER_AREA);
  if (frames_ == 0) first_stamp_ = stamp;
  last_stamp_ = stamp;
  if (!prev_grey_.empty()) {
    std::vector<cv::Point2f> a, b, back;
    cv::goodFeaturesToTrack(prev_grey_, a, options_.max_features, 0.01,
                            std::max(4.0, 0.02 * prev_grey_.cols));
    Pair p;
    p.a = prev_stamp_;
    p.b = stamp;
    if (!a.empty()) {
      std::vector<uchar> st, st2;
      std::vector<float> err;
      cv::calcOpticalFlowPyrLK(prev_grey_, grey, a, b, st, err);
      cv::calcOpticalFlowPyrLK(grey, prev_grey_, b, back, st2, err);
      for (size_t i = 0; i < a.size(); ++i) {
        if (!st[i] || !st2[i] ||
            cv::norm(back[i] - a[i]) > options_.max_fb_error_px)
          continue;
        const Eigen::Vector2d ra(a[i].x / scale_, a[i].y / scale_),
            rb(b[i].x / scale_, b[i].y / scale_);
        if (rb.x() < 0 || rb.y() < 0 || rb.x() > k_.width - 1 ||
            rb.y() > k_.height - 1)
          continue;
        Eigen::Vector2d ua, ub;
        if (!UndistortPixel(k_, ra, &ua) || !UndistortPixel(k_, rb, &ub))
          continue;
        p.ray_a.emplace_back((ua.x() - k_.cx) / k_.fx, (ua.y() - k_.cy) / k_.fy,
                             1.0);
        p.px_b.push_back(ub);
        p.row_a.push_back(ra.y());
        p.row_b.push_back(rb.y());
      }
    }
    pairs_.push_back(std::move(p));
  }
  prev_grey_ = grey.clone();
  prev_stamp_ = stamp;
  ++frames_;
  return Status::Ok();
}

Status Calibrator::Solve(CalibrationResult* result) {
  CalibrationResult res;
  const CalibratorOptions& o = options_;
  res.duration_s = frames_ > 1 ? ToSeconds(last_stamp_ - first_stamp_) : 0.0;
  const Status length = CheckLength(res.duration_s);
  if (!length.ok()) return length;
  std::sort(gyro_.begin(), gyro_.end(),
            [](const GyroSample& a, const GyroSample& b) { return a.stamp < b.stamp; });
  const GyroIntegral g(gyro_);
  const double H1 = k_.height - 1.0, s_share = StampShare(shutter_.stamp);
  const double row_off = shutter_.row_time_offset_s;
  auto rel = [&](Time t) { return ToSeconds(t - g.origin()) + row_off; };
  const double video_begin = rel(first_stamp_), video_end = rel(last_stamp_);
  std::vector<const Pair*> good;
  size_t tracks = 0;
  Status s = CheckRecording(g, video_begin, video_end, &good, &tracks, &res);
  if (!s.ok()) return s;
  // 1. Video rotation per pair; 2. coarse offset; 3. rotation (Wahba).
  const std::vector<VideoRotation> video =
      VideoRotations(good, k_, shutter_.readout_time_s * (0.5 - s_share), rel);
  res.coarse_offset_s =
      CoarseOffset(video, g, initial_offset_s_, o.coarse_range_s, o.coarse_step_s);
  const Eigen::Matrix3d R0 = WahbaRotation(video, g, res.coarse_offset_s);
  // 4. Ceres over every track.
  double q[4], offset[1] = {res.coarse_offset_s},
               readout[1] = {shutter_.readout_time_s}, bias[3] = {0, 0, 0};
  Eigen::Map<Eigen::Quaterniond> q_map(q);
  q_map = Eigen::Quaterniond(R0).normalized();
  std::vector<double> frame_dt;
  for (const Pair* p : good) frame_dt.push_back(ToSeconds(p->b - p->a));
  const double period = Percentile(frame_dt, 0.5);
  struct Obs {
    const Pair* p;
    size_t i;
  };
  std::vector<Obs> obs;
  for (const Pair* p : good) {
    for (size_t i = 0; i < p->ray_a.size(); ++i) obs.push_back({p, i});
  }
  auto make_cost = [&](const Obs& ob) {
    const Pair& p = *ob.p;
    return TrackCost::Create(&g, k_, p.ray_a[ob.i], p.px_b[ob.i], rel(p.a),
                             p.row_a[ob.i] / H1 - s_share, rel(p.b),
                             p.row_b[ob.i] / H1 - s_share);
  };
  auto residual_of = [&](const Obs& ob, const double* qq, const double* off,
                         const double* ro, const double* bi) {
    std::unique_ptr<ceres::CostFunction> c(make_cost(ob));
    const double* params[4] = {qq, off, ro, bi};
    double r[2];
    if (!c->Evaluate(params, r, nullptr)) return 1e3;
    return std::hypot(r[0], r[1]);
  };
  res.residual_before_px =
      MedianResidual(obs, residual_of, initial_R_, initial_offset_s_, shutter_.readout_time_s);
  std::vector<bool> keep(obs.size(), true);
  std::unique_ptr<ceres::Problem> problem = SolveTracks(
      obs, make_cost, residual_of, period, o, q, offset, readout, bias, &keep, &res.solver_report);
  const double sigma2 =
      ResidualSpread(obs, residual_of, keep, q, offset, readout, bias, &res.residual_after_px);
  const bool have_cov = Sigmas(problem.get(), q, offset, readout, bias, sigma2, o, &res);
  res.R_cam_imu = Eigen::Map<Eigen::Quaterniond>(q).normalized();
  res.time_offset_s = offset[0];
  res.readout_s = readout[0];
  res.bias = Eigen::Vector3d(bias[0], bias[1], bias[2]);
  res.pairs = static_cast<int>(good.size());
  res.tracks = static_cast<int>(tracks);
  res.readout_determined =
      o.estimate_readout && have_cov && res.readout_sigma_s <= o.max_readout_sigma_s;
  NearestPermutation(&res);
  AddPlots(video, g, video_begin, initial_offset_s_, &res);
  *result = res;
  return Determined(res, have_cov);
}

}  // namespace steadiface

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

#include "steadiface_core/calibration/gyro_integral.h"
#include "steadiface_core/camera/lens_distortion.h"
#include "steadiface_core/check/gyro_video_check.h"
#include "steadiface_core/common/ceres_compat.h"
#include "steadiface_core/common/grey.h"
#include "steadiface_core/common/percentile.h"
#include "steadiface_core/common/so3.h"

namespace steadiface {
namespace {

// Fraction of the readout from the stamp to row y: t(y) = stamp +
// readout * (y / (H - 1) - s) + row_time_offset.
double StampShare(StampConvention c) {
  return c == StampConvention::kFirstRow    ? 0.0
         : c == StampConvention::kMiddleRow ? 0.5
                                            : 1.0;
}

// One track between two frames: the ray of frame a moves by the camera's
// rotation between the two rows' times, predicted by the gyro:
//   theta = R_cam_imu (I(t_b - offset) - I(t_a - offset) - bias (t_b - t_a))
//   ray_b = Exp(-theta) ray_a          (R_r = C^T, C' = C [omega]x)
// Residual (2): the predicted pixel minus the tracked one [px].
struct TrackCost {
  TrackCost(const GyroIntegral* g, const CameraIntrinsics& k,
            const Eigen::Vector3d& ray_a, const Eigen::Vector2d& px_b,
            double sa, double fa, double sb, double fb)
      : g_(g),
        k_(k),
        ray_a_(ray_a),
        px_b_(px_b),
        sa_(sa),
        fa_(fa),
        sb_(sb),
        fb_(fb) {}

  template <typename T>
  bool operator()(const T* q, const T* offset, const T* readout, const T* bias,
                  T* r) const {
    const T ta = T(sa_) + readout[0] * T(fa_) - offset[0];
    const T tb = T(sb_) + readout[0] * T(fb_) - offset[0];
    const Eigen::Matrix<T, 3, 1> b(bias[0], bias[1], bias[2]);
    const Eigen::Matrix<T, 3, 1> dI = g_->At(tb) - g_->At(ta) - b * (tb - ta);
    const Eigen::Map<const Eigen::Quaternion<T>> R(q);
    const Eigen::Matrix<T, 3, 1> theta = -(R * dI);
    const T ray[3] = {T(ray_a_.x()), T(ray_a_.y()), T(ray_a_.z())};
    T rb[3];
    ceres::AngleAxisRotatePoint(theta.data(), ray, rb);
    if (!(rb[2] > T(1e-6))) return false;
    r[0] = T(k_.fx) * rb[0] / rb[2] + T(k_.cx) - T(px_b_.x());
    r[1] = T(k_.fy) * rb[1] / rb[2] + T(k_.cy) - T(px_b_.y());
    return true;
  }

  static ceres::CostFunction* Create(const GyroIntegral* g,
                                     const CameraIntrinsics& k,
                                     const Eigen::Vector3d& ray_a,
                                     const Eigen::Vector2d& px_b, double sa,
                                     double fa, double sb, double fb) {
    // Residuals: 2; parameters: R_cam_imu (4), offset (1), readout (1), bias
    // (3).
    return new ceres::AutoDiffCostFunction<TrackCost, 2, 4, 1, 1, 3>(
        new TrackCost(g, k, ray_a, px_b, sa, fa, sb, fb));
  }

  const GyroIntegral* g_;
  const CameraIntrinsics k_;
  const Eigen::Vector3d ray_a_;
  const Eigen::Vector2d px_b_;
  const double sa_, fa_, sb_,
      fb_;  // stamp [s since the gyro origin], readout share
};

// The rotation Q with b ~ Q a (Kabsch), unit vectors.
Eigen::Matrix3d Kabsch(const std::vector<Eigen::Vector3d>& a,
                       const std::vector<Eigen::Vector3d>& b,
                       const std::vector<bool>& use) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < a.size(); ++i) {
    if (use[i]) H += a[i] * b[i].transpose();
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(
      H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double d = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0
                       ? -1.0
                       : 1.0;
  return svd.matrixV() * Eigen::Vector3d(1, 1, d).asDiagonal() *
         svd.matrixU().transpose();
}

// One frame pair's rotation from the video: mid-row times [s since the
// gyro origin] and the camera-frame rotation, C_a^T C_b = Exp(theta).
struct VideoRotation {
  double ta, tb;
  Eigen::Vector3d theta;
};

// The gyro's rotation over a pair's times at a clock offset.
Eigen::Vector3d GyroTheta(const GyroIntegral& g, const VideoRotation& v, double offset) {
  return g.At(v.tb - offset) - g.At(v.ta - offset);
}

// The gyro's mean angular speed over [begin, end] (every 10 ms).
double MeanAngularSpeed(const GyroIntegral& g, double begin, double end, double offset) {
  double sum = 0.0;
  int n = 0;
  for (double t = begin; t <= end; t += 0.01, ++n) sum += g.Rate(t - offset).norm();
  return n ? sum / n : 0.0;
}

// Kabsch on each pair's rays, one outlier pass (3x the median error).
// `rel` maps a stamp to seconds since the gyro origin; `mid` moves it to
// the middle row.
template <typename PairT, typename Rel>
std::vector<VideoRotation> VideoRotations(const std::vector<const PairT*>& good,
                                          const CameraIntrinsics& k, double mid, const Rel& rel) {
  std::vector<VideoRotation> video;
  for (const PairT* p : good) {
    const size_t n = p->ray_a.size();
    std::vector<Eigen::Vector3d> a(n), b(n);
    for (size_t i = 0; i < n; ++i) {
      a[i] = p->ray_a[i].normalized();
      b[i] = Eigen::Vector3d((p->px_b[i].x() - k.cx) / k.fx, (p->px_b[i].y() - k.cy) / k.fy, 1.0)
                 .normalized();
    }
    std::vector<bool> use(n, true);
    Eigen::Matrix3d Q = Kabsch(a, b, use);
    std::vector<double> err(n);
    for (size_t i = 0; i < n; ++i) err[i] = (Q * a[i] - b[i]).norm();
    const double cut = 3.0 * Percentile(err, 0.5) + 1e-9;
    for (size_t i = 0; i < n; ++i) use[i] = err[i] <= cut;
    Q = Kabsch(a, b, use);
    video.push_back({rel(p->a) + mid, rel(p->b) + mid, -LogSO3(Eigen::Quaterniond(Q))});
  }
  return video;
}

// The offset whose gyro rotation magnitudes best match the video's (free of
// the mounting), searched in steps over +-range around `initial`.
double CoarseOffset(const std::vector<VideoRotation>& video, const GyroIntegral& g,
                    double initial, double range, double step) {
  double best = std::numeric_limits<double>::infinity(), offset_best = initial;
  for (double d = -range; d <= range + 1e-12; d += step) {
    const double offset = initial + d;
    double cost = 0.0;
    for (const VideoRotation& v : video) {
      const double e = v.theta.norm() - GyroTheta(g, v, offset).norm();
      cost += e * e;
    }
    if (cost < best) {
      best = cost;
      offset_best = offset;
    }
  }
  return offset_best;
}

// Wahba's problem: the rotation R with theta_video ~ R theta_gyro.
Eigen::Matrix3d WahbaRotation(const std::vector<VideoRotation>& video, const GyroIntegral& g,
                              double offset) {
  Eigen::Matrix3d B = Eigen::Matrix3d::Zero();
  for (const VideoRotation& v : video) B += v.theta * GyroTheta(g, v, offset).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(B, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const double d = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixU() * Eigen::Vector3d(1, 1, d).asDiagonal() * svd.matrixV().transpose();
}

// The parameters' 1-sigma from Ceres' covariance scaled by the residuals'
// spread sigma2; false when it cannot be computed.
bool Sigmas(ceres::Problem* problem, double* q, double* offset, double* readout, double* bias,
            double sigma2, const CalibratorOptions& o, CalibrationResult* res) {
  ceres::Covariance::Options co;
  ceres::Covariance cov(co);
  std::vector<std::pair<const double*, const double*>> blocks = {
      {q, q}, {offset, offset}, {readout, readout}, {bias, bias}};
  if (!cov.Compute(blocks, problem)) return false;
  double cq[9], co1[1], cr[1], cb[9];
  cov.GetCovarianceBlockInTangentSpace(q, q, cq);
  cov.GetCovarianceBlock(offset, offset, co1);
  if (o.estimate_readout) cov.GetCovarianceBlock(readout, readout, cr);
  if (o.estimate_bias) cov.GetCovarianceBlock(bias, bias, cb);
  const Eigen::Map<Eigen::Matrix3d> Cq(cq);
  // The quaternion's tangent (ceres_compat.h): Plus(x, delta) turns by 2 |delta|.
  res->rotation_sigma_deg =
      2.0 * std::sqrt(std::max(0.0, sigma2 * Cq.eigenvalues().real().maxCoeff())) * 180.0 / M_PI;
  res->time_offset_sigma_s = std::sqrt(std::max(0.0, sigma2 * co1[0]));
  res->readout_sigma_s = o.estimate_readout ? std::sqrt(std::max(0.0, sigma2 * cr[0])) : 0.0;
  if (o.estimate_bias) {
    for (int i = 0; i < 3; ++i) res->bias_sigma(i) = std::sqrt(std::max(0.0, sigma2 * cb[4 * i]));
  }
  return true;
}

// The median track residual at a given mounting, offset and readout, no
// bias (the "before" of the report).
template <typename Obs, typename Residual>
double MedianResidual(const std::vector<Obs>& obs, const Residual& residual_of,
                      const Eigen::Quaterniond& R, double offset_s, double readout_s) {
  double q0[4], off0[1] = {offset_s}, ro0[1] = {readout_s}, b0[3] = {0, 0, 0};
  Eigen::Map<Eigen::Quaterniond> q0_map(q0);
  q0_map = R;
  std::vector<double> r;
  for (const Obs& ob : obs) r.push_back(residual_of(ob, q0, off0, ro0, b0));
  return Percentile(r, 0.5);
}

// Ceres over the tracks, twice: the second pass without the tracks whose
// residual exceeds 3 px after the first. Returns the last problem (for the
// covariance); the solver's brief report into *report.
template <typename Obs, typename MakeCost, typename Residual>
std::unique_ptr<ceres::Problem> SolveTracks(const std::vector<Obs>& obs, const MakeCost& make_cost,
                                            const Residual& residual_of, double period,
                                            const CalibratorOptions& o, double* q, double* offset,
                                            double* readout, double* bias, std::vector<bool>* keep,
                                            std::string* report) {
  std::unique_ptr<ceres::Problem> problem;
  for (int pass = 0; pass < 2; ++pass) {
    problem.reset(new ceres::Problem);
    for (size_t j = 0; j < obs.size(); ++j) {
      if (!(*keep)[j]) continue;
      problem->AddResidualBlock(make_cost(obs[j]), new ceres::CauchyLoss(o.loss_scale_px), q,
                                offset, readout, bias);
    }
    ceres_compat::SetQuaternionManifold(problem.get(), q);
    problem->SetParameterLowerBound(readout, 0, 0.0);
    problem->SetParameterUpperBound(readout, 0, std::max(1e-4, period));
    if (!o.estimate_readout) problem->SetParameterBlockConstant(readout);
    if (!o.estimate_bias) problem->SetParameterBlockConstant(bias);
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = 50;
    so.num_threads = 1;
    ceres::Solver::Summary summary;
    ceres::Solve(so, problem.get(), &summary);
    *report = summary.BriefReport();
    if (pass == 0) {
      for (size_t j = 0; j < obs.size(); ++j) {
        (*keep)[j] = residual_of(obs[j], q, offset, readout, bias) <= 3.0;
      }
    }
  }
  return problem;
}

// The median residual over every track into *median, and the kept tracks'
// residual variance per coordinate (2 per track, 9 parameters), which
// scales the covariance.
template <typename Obs, typename Residual>
double ResidualSpread(const std::vector<Obs>& obs, const Residual& residual_of,
                      const std::vector<bool>& keep, const double* q, const double* offset,
                      const double* readout, const double* bias, double* median) {
  std::vector<double> r;
  double sq = 0.0;
  int used = 0;
  for (size_t j = 0; j < obs.size(); ++j) {
    const double e = residual_of(obs[j], q, offset, readout, bias);
    r.push_back(e);
    if (keep[j]) {
      sq += e * e;
      ++used;
    }
  }
  *median = Percentile(r, 0.5);
  return used > 9 ? sq / (2.0 * used - 9.0) : 1.0;
}

// The signed axis permutation nearest to the estimated mounting.
void NearestPermutation(CalibrationResult* res) {
  double best_angle = 1e9;
  for (const Eigen::Quaterniond& P : GyroVideoCheck::SignedAxisPermutations()) {
    const double a = res->R_cam_imu.angularDistance(P);
    if (a < best_angle) {
      best_angle = a;
      res->nearest_permutation = P;
    }
  }
  res->misalignment_deg = best_angle * 180.0 / M_PI;
}

// Plots: angular speed from the video and from the gyro, before (initial
// offset, no bias) and after.
void AddPlots(const std::vector<VideoRotation>& video, const GyroIntegral& g, double t0,
              double initial_offset_s, CalibrationResult* res) {
  for (const VideoRotation& v : video) {
    const double dt = v.tb - v.ta;
    res->plot_t.push_back(0.5 * (v.ta + v.tb) - t0);
    res->plot_video.push_back(v.theta.norm() / dt);
    res->plot_gyro_before.push_back(GyroTheta(g, v, initial_offset_s).norm() / dt);
    res->plot_gyro_after.push_back((GyroTheta(g, v, res->time_offset_s) - res->bias * dt).norm() /
                                   dt);
  }
}

}  // namespace

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

Status Calibrator::CheckLength(double duration_s) const {
  // Enough video and any IMU data at all.
  const CalibratorOptions& o = options_;
  if (frames_ < 2 || duration_s < o.min_duration_s) {
    std::ostringstream e;
    e << "calibrate: the recording is " << duration_s << " s long ("
      << frames_ << " frames); at least " << o.min_duration_s
      << " s of video is needed";
    return Status::Error(e.str());
  }
  if (gyro_.size() < 10) {
    return Status::Error(
        "calibrate: no IMU data (" + std::to_string(gyro_.size()) +
        " gyro samples); record the IMU topic with the images");
  }
  return Status::Ok();
}

Status Calibrator::CheckRecording(const GyroIntegral& g, double video_begin, double video_end,
                                  std::vector<const Pair*>* good_out, size_t* tracks_out,
                                  CalibrationResult* out) const {
  // The gyro covers the video, enough pairs have enough tracks, and the
  // camera turned enough; the good pairs and their track count.
  const CalibratorOptions& o = options_;
  CalibrationResult& res = *out;
  std::vector<const Pair*>& good = *good_out;
  size_t& tracks = *tracks_out;
  // The gyro must cover the video on the camera clock (t_imu = t_cam - offset).
  if (g.begin() > video_begin - initial_offset_s_ + 0.05 ||
      g.end() <
          video_end - initial_offset_s_ + shutter_.readout_time_s - 0.05) {
    std::ostringstream e;
    e << "calibrate: the IMU samples (" << g.end() - g.begin()
      << " s) do not cover the video with imu/time_offset " << initial_offset_s_
      << " s; check the IMU topic and the offset's sign";
    return Status::Error(e.str());
  }
  // Pairs with enough tracks.
  for (const Pair& p : pairs_) {
    if (static_cast<int>(p.ray_a.size()) >= o.min_tracks) {
      good.push_back(&p);
      tracks += p.ray_a.size();
    }
  }
  if (static_cast<int>(good.size()) < o.min_pairs) {
    std::ostringstream e;
    e << "calibrate: too few trackable features: " << good.size() << " of "
      << pairs_.size() << " frame pairs have " << o.min_tracks
      << " or more tracks (need " << o.min_pairs
      << "; a dark, blurred or textureless video?)";
    return Status::Error(e.str());
  }
  res.mean_angular_speed = MeanAngularSpeed(g, video_begin, video_end, initial_offset_s_);
  if (res.mean_angular_speed < o.min_angular_speed) {
    std::ostringstream e;
    e << "calibrate: too little rotation: the gyro's mean |omega| is "
      << res.mean_angular_speed << " rad/s, " << o.min_angular_speed
      << " rad/s or more is needed (shake or turn the camera for a few "
         "seconds)";
    return Status::Error(e.str());
  }
  return Status::Ok();
}

Status Calibrator::Determined(const CalibrationResult& res, bool have_cov) const {
  // The clock offset and the rotation must be determined.
  const CalibratorOptions& o = options_;
  if (!have_cov || !(res.time_offset_sigma_s <= o.max_offset_sigma_s)) {
    std::ostringstream e;
    e << "calibrate: the clock offset is not determined (1-sigma "
      << res.time_offset_sigma_s * 1e3 << " ms > " << o.max_offset_sigma_s * 1e3
      << " ms): more varied shake is needed";
    return Status::Error(e.str());
  }
  if (!(res.rotation_sigma_deg <= 2.0)) {
    std::ostringstream e;
    e << "calibrate: the IMU rotation is not determined (1-sigma "
      << res.rotation_sigma_deg
      << " deg > 2 deg): rotate the camera about more than one axis";
    return Status::Error(e.str());
  }
  return Status::Ok();
}

}  // namespace steadiface

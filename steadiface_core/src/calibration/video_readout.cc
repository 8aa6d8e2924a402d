#include "steadiface_core/calibration/video_readout.h"

#include <algorithm>
#include <cmath>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/common/percentile.h"

namespace steadiface {
namespace {

constexpr double kSigma = 2.5;  // the low-pass's Gaussian [pairs]

// The fit's priors for calibration: the within-frame rate of change left
// free (it is what is measured), its curvature as in the pipeline.
VisualRotationOptions CalibrationVisualOptions() {
  VisualRotationOptions o;
  o.alpha_prior_rad_s2 = 1e4;
  o.beta_prior_rad_s3 = 1000.0;
  return o;
}

// Least squares through the origin of y on x, with the points beyond 3
// robust sigma of the first fit's residuals dropped: the slope, its formal
// sigma, the correlation and the points kept.
struct Slope {
  double k = NAN, sigma = NAN, correlation = 0.0;
  int n = 0;
};

Slope FitSlope(const std::vector<double>& x, const std::vector<double>& y) {
  Slope s;
  std::vector<bool> use(x.size(), true);
  for (int round = 0; round < 2; ++round) {
    double sxy = 0.0, sxx = 0.0, syy = 0.0;
    int n = 0;
    for (size_t i = 0; i < x.size(); ++i) {
      if (!use[i]) continue;
      sxy += x[i] * y[i];
      sxx += x[i] * x[i];
      syy += y[i] * y[i];
      ++n;
    }
    if (n < 3 || sxx <= 0.0 || syy <= 0.0) return s;
    s.k = sxy / sxx;
    s.n = n;
    s.correlation = sxy / std::sqrt(sxx * syy);
    std::vector<double> res;
    double ss = 0.0;
    for (size_t i = 0; i < x.size(); ++i) {
      if (!use[i]) continue;
      res.push_back(std::abs(y[i] - s.k * x[i]));
      ss += res.back() * res.back();
    }
    s.sigma = std::sqrt(ss / (n - 1) / sxx);
    const double robust = 1.4826 * Percentile(res, 0.5);
    for (size_t i = 0; i < x.size(); ++i) {
      if (std::abs(y[i] - s.k * x[i]) > 3.0 * robust) use[i] = false;
    }
  }
  return s;
}

}  // namespace

Status VideoReadoutEstimator::Create(const CameraIntrinsics& intrinsics,
                                     const RollingShutterOptions& shutter,
                                     const VideoReadoutOptions& options,
                                     std::unique_ptr<VideoReadoutEstimator>* out) {
  Status s = ValidateRollingShutterOptions(shutter);
  if (!s.ok()) return s;
  if (options.min_triples < 3 || !(options.min_correlation >= 0.0) ||
      !(options.max_sigma_s > 0.0) ||
      !(std::isnan(options.nominal_readout_s) || options.nominal_readout_s > 0.0)) {
    return Status::Error(
        "video readout: min_triples >= 3, min_correlation >= 0, max_sigma_s > 0 and a "
        "positive (or NaN) nominal readout are needed");
  }
  out->reset(new VideoReadoutEstimator(intrinsics, shutter, options));
  return Status::Ok();
}

VideoReadoutEstimator::VideoReadoutEstimator(const CameraIntrinsics& intrinsics,
                                             const RollingShutterOptions& shutter,
                                             const VideoReadoutOptions& options)
    : intrinsics_(intrinsics), shutter_(shutter), options_(options) {}

Status VideoReadoutEstimator::Start(Time stamp) {
  r0_ = options_.nominal_readout_s;
  if (std::isnan(r0_)) r0_ = 0.5 * ToSeconds(stamp - first_stamp_);
  if (!(r0_ > 0.0 && r0_ < 1.0)) {
    return Status::Error("video readout: the first two frames are not 0-2 s apart");
  }
  RollingShutterOptions rs = shutter_;
  rs.readout_time_s = r0_;
  CameraModel model;
  Status s = CameraModel::Create(intrinsics_, CameraModelOptions(), &model);
  if (s.ok()) {
    s = VisualRotationEstimator::Create(model, RowTiming(rs, intrinsics_.height),
                                        CalibrationVisualOptions(), &visual_);
  }
  VisualRotation first;
  if (s.ok()) s = visual_->Process(first_, first_stamp_, cv::Rect2d(), &first);
  first_.release();
  return s;
}

Status VideoReadoutEstimator::AddFrame(const cv::Mat& grey, Time stamp) {
  if (grey.empty() || grey.type() != CV_8UC1 || grey.cols != intrinsics_.width ||
      grey.rows != intrinsics_.height) {
    return Status::Error("video readout: need 8-bit grey frames at the intrinsics' size");
  }
  ++frames_;
  if (frames_ == 1) {
    first_ = grey.clone();
    first_stamp_ = stamp;
    return Status::Ok();
  }
  if (!visual_) {
    Status s = Start(stamp);
    if (!s.ok()) return s;
  }
  VisualRotation r;
  Status s = visual_->Process(grey, stamp, cv::Rect2d(), &r);
  if (!s.ok()) return s;
  pairs_.push_back(r);
  return Status::Ok();
}

VideoReadoutResult VideoReadoutEstimator::Estimate() const {
  VideoReadoutResult out;
  // The rate of change within a pair (fitted with r0) against the one
  // across the neighbouring pairs, per axis. Both are low-passed alike (a Gaussian over kSigma pairs): the rows'
  // spread within a pair sees the difference of the instantaneous rates one
  // frame apart, the pairs' rates are means over a frame, and the two agree
  // only well below the frame rate (at f: 2 pi f T / sin(2 pi f T); 1.07 at
  // 3 Hz, 2.4 at 10 Hz with T = 1/30 s).
  std::vector<double> across, within;
  double rate2 = 0.0, accel2 = 0.0, spacing = 0.0;  // for the shake's frequency
  const int half = static_cast<int>(std::ceil(3.0 * kSigma));
  for (int n = half + 1; n + half + 1 < static_cast<int>(pairs_.size()); ++n) {
    Eigen::Vector3d fd = Eigen::Vector3d::Zero(), al = Eigen::Vector3d::Zero();
    Eigen::Vector3d om = Eigen::Vector3d::Zero();
    double wsum = 0.0;
    bool ok = true;
    for (int m = n - half; m <= n + half && ok; ++m) {
      const VisualRotation &a = pairs_[m - 1], &b = pairs_[m], &c = pairs_[m + 1];
      const double dt = ToSeconds(c.stamp - a.stamp);
      ok = a.valid && b.valid && c.valid && dt > 0.0;
      const double w = std::exp(-0.5 * (m - n) * (m - n) / (kSigma * kSigma));
      if (ok) {
        fd += w * (c.omega - a.omega) / dt;
        al += w * b.alpha;
        om += w * b.omega;
        wsum += w;
      }
    }
    if (!ok) continue;
    for (int i = 0; i < 3; ++i) {
      across.push_back(fd[i] / wsum);
      within.push_back(al[i] / wsum);
    }
    // The low-passed rate and its change, for the shake's RMS frequency.
    // The rate's mean is not removed: a pan lowers that frequency, and the
    // correction below with it.
    rate2 += (om / wsum).squaredNorm();
    accel2 += (fd / wsum).squaredNorm();
    spacing += ToSeconds(pairs_[n + 1].stamp - pairs_[n].stamp);
    ++out.triples;
  }
  // What is left of the mismatch below the low-pass: at the shake's RMS
  // frequency f, the within measure is x / sin(x), x = 2 pi f T, times the
  // across one; divided out (1.02 at 1.5 Hz, 1.07 at 3 Hz).
  double x = 0.0;
  if (out.triples > 0 && rate2 > 0.0) {
    x = std::sqrt(accel2 / rate2) * spacing / out.triples;  // 2 pi f T
    out.shake_hz = std::sqrt(accel2 / rate2) / (2.0 * M_PI);
  }
  const double mismatch = x > 1e-6 && x < 1.5 ? x / std::sin(x) : 1.0;
  const Slope s = FitSlope(across, within);
  out.correlation = s.correlation;
  // within = across x r / r0, so r = r0 x slope.
  out.readout_s = r0_ * s.k / mismatch;
  out.sigma_s = r0_ * s.sigma / mismatch;
  if (out.triples < options_.min_triples) {
    out.reason = "too few frame triples with a trusted rotation from the video (" +
                 std::to_string(out.triples) + ")";
  } else if (!(s.correlation >= options_.min_correlation)) {
    out.reason = "the camera's rotation does not change enough from frame to frame (hold it "
                 "by hand and shake it a little)";
  } else if (!(x < 1.0)) {
    out.reason = "the shake is too fast for the frame rate to follow";
  } else if (!(out.sigma_s <= options_.max_sigma_s)) {
    out.reason = "the estimate is too uncertain";
  } else if (!(out.readout_s >= 0.0)) {
    out.reason = "the estimate is negative";
  }
  out.determined = out.reason.empty();
  return out;
}

}  // namespace steadiface

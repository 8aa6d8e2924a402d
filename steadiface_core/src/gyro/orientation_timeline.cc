#include "steadiface_core/gyro/orientation_timeline.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "steadiface_core/common/so3.h"

namespace steadiface {

Status ValidateOrientationTimelineOptions(
    const OrientationTimelineOptions& o) {
  std::ostringstream err;
  const double qn = o.R_cam_imu.norm();
  if (!o.R_cam_imu.coeffs().allFinite() || std::abs(qn - 1.0) > 1e-6) {
    err << "imu.R_cam_imu must be a finite unit quaternion, norm=" << qn;
  } else if (!o.gyro_bias.allFinite() || o.gyro_bias.norm() >= 1.0) {
    err << "imu.gyro_bias must be finite with |bias| < 1 rad/s, got |bias|="
        << o.gyro_bias.norm();
  } else if (!std::isfinite(o.imu_time_offset_s) ||
             std::abs(o.imu_time_offset_s) > 1.0) {
    err << "imu.time_offset must be in [-1, 1] s, got " << o.imu_time_offset_s;
  } else if (!std::isfinite(o.buffer_duration_s) || o.buffer_duration_s < 0.5 ||
             o.buffer_duration_s > 600.0) {
    err << "imu.buffer_duration must be in [0.5, 600] s, got "
        << o.buffer_duration_s;
  } else if (o.max_samples < 16 || o.max_samples > 10000000) {
    err << "imu.max_samples must be in [16, 1e7], got " << o.max_samples;
  } else if (!std::isfinite(o.max_angular_rate) || o.max_angular_rate <= 0.0) {
    err << "imu.max_angular_rate must be > 0 rad/s, got "
        << o.max_angular_rate;
  } else if (!std::isfinite(o.max_gap_s) || o.max_gap_s <= 0.0) {
    err << "imu.max_gap must be > 0 s, got " << o.max_gap_s;
  } else if (!std::isfinite(o.max_extrapolation_s) ||
             o.max_extrapolation_s < 0.0 || o.max_extrapolation_s > 1.0) {
    err << "imu.max_extrapolation must be in [0, 1] s, got "
        << o.max_extrapolation_s;
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

const char* SampleResultName(SampleResult r) {
  switch (r) {
    case SampleResult::kAccepted:
      return "accepted";
    case SampleResult::kNonFinite:
      return "non_finite";
    case SampleResult::kImplausibleRate:
      return "implausible_rate";
    case SampleResult::kDuplicateStamp:
      return "duplicate_stamp";
    case SampleResult::kOutOfOrder:
      return "out_of_order";
    case SampleResult::kCount:
      break;
  }
  return "unknown";
}

uint64_t TimelineStats::rejected() const {
  uint64_t n = 0;
  for (size_t i = 1; i < samples.size(); ++i) n += samples[i];
  return n;
}

OrientationTimeline::OrientationTimeline(
    const OrientationTimelineOptions& options)
    : options_(options),
      time_offset_(FromSeconds(options.imu_time_offset_s)),
      buffer_duration_(FromSeconds(options.buffer_duration_s)) {}

SampleResult OrientationTimeline::AddSample(const GyroSample& sample) {
  SampleResult result = SampleResult::kAccepted;
  const Eigen::Vector3d omega =
      options_.R_cam_imu.normalized() * (sample.angular_velocity - options_.gyro_bias);
  const Time t = sample.stamp + time_offset_;
  if (!sample.angular_velocity.allFinite()) {
    result = SampleResult::kNonFinite;
  } else if (omega.norm() > options_.max_angular_rate) {
    result = SampleResult::kImplausibleRate;
  } else if (!samples_.empty() && t == samples_.back().t) {
    result = SampleResult::kDuplicateStamp;
  } else if (!samples_.empty() && t < samples_.back().t) {
    result = SampleResult::kOutOfOrder;
  }
  ++stats_.samples[static_cast<size_t>(result)];
  if (result != SampleResult::kAccepted) return result;

  if (samples_.empty()) {
    samples_.push_back(Node{t, omega, Eigen::Quaterniond::Identity()});
    return result;
  }
  const Node& prev = samples_.back();
  const double dt = ToSeconds(t - prev.t);
  if (dt > options_.max_gap_s) ++stats_.gaps;
  // First Magnus term: the integral of omega over [t_prev, t]. With a sample
  // before prev (and no gap) integrate the quadratic through the last three
  // samples (third-order quadrature, nonuniform spacing allowed); otherwise
  // the trapezoid rule.
  Eigen::Vector3d integral;
  const double h2 = dt;
  const double h1 = samples_.size() >= 2
                        ? ToSeconds(prev.t - samples_[samples_.size() - 2].t)
                        : 0.0;
  if (samples_.size() >= 2 && dt <= options_.max_gap_s && h1 > 0.0 &&
      h1 <= options_.max_gap_s && h1 < 4.0 * h2 && h2 < 4.0 * h1) {
    const Eigen::Vector3d& w0 = samples_[samples_.size() - 2].omega;
    const double c0 = -h2 * h2 * h2 / (6.0 * h1 * (h1 + h2));
    const double c1 = h2 * h2 / (6.0 * h1) + 0.5 * h2;
    const double c2 = (h2 * h2 / 3.0 + 0.5 * h1 * h2) / (h1 + h2);
    integral = c0 * w0 + c1 * prev.omega + c2 * omega;
  } else {
    integral = 0.5 * dt * (prev.omega + omega);
  }
  // Second Magnus term for omega varying linearly across the step.
  const Eigen::Vector3d phi =
      integral + (dt * dt / 12.0) * prev.omega.cross(omega);
  Eigen::Quaterniond q = prev.q_wc * ExpSO3(phi);
  q.normalize();
  samples_.push_back(Node{t, omega, q});
  Trim();
  return result;
}

SampleResult OrientationTimeline::AddOrientation(Time t, const Eigen::Quaterniond& q_wc,
                                                 const Eigen::Vector3d& omega) {
  SampleResult result = SampleResult::kAccepted;
  const Time stored = t - correction_;
  if (!omega.allFinite() || !q_wc.coeffs().allFinite() || q_wc.norm() < 0.5) {
    result = SampleResult::kNonFinite;
  } else if (omega.norm() > options_.max_angular_rate) {
    result = SampleResult::kImplausibleRate;
  } else if (!samples_.empty() && stored == samples_.back().t) {
    result = SampleResult::kDuplicateStamp;
  } else if (!samples_.empty() && stored < samples_.back().t) {
    result = SampleResult::kOutOfOrder;
  }
  ++stats_.samples[static_cast<size_t>(result)];
  if (result != SampleResult::kAccepted) return result;
  // Stored like a gyro sample: a query at camera time t, which reads the
  // samples at t - correction, finds it.
  samples_.push_back(Node{stored, omega, q_wc.normalized()});
  Trim();
  return result;
}

void OrientationTimeline::Trim() {
  const Time horizon = samples_.back().t - buffer_duration_;
  while (samples_.size() > 2 &&
         (samples_.front().t < horizon ||
          samples_.size() > static_cast<size_t>(options_.max_samples))) {
    samples_.pop_front();
    ++stats_.trimmed;
  }
}

size_t OrientationTimeline::Bracket(Time t) const {
  // Last index i with samples_[i].t <= t.
  auto it = std::upper_bound(
      samples_.begin(), samples_.end(), t,
      [](const Time& value, const Node& n) { return value < n.t; });
  return static_cast<size_t>(std::distance(samples_.begin(), it)) - 1;
}

QueryResult OrientationTimeline::CameraToWorld(Time t_cam,
                                               Eigen::Quaterniond* q_wc) const {
  if (samples_.empty()) return QueryResult::kEmpty;
  const Time t = t_cam - correction_;
  if (t < samples_.front().t) return QueryResult::kBeforeStart;
  const Node& last = samples_.back();
  if (t > last.t) {
    const double dt = ToSeconds(t - last.t);
    if (dt > options_.max_extrapolation_s) return QueryResult::kAfterEnd;
    *q_wc = (last.q_wc * ExpSO3(last.omega * dt)).normalized();
    return QueryResult::kExtrapolated;
  }
  const size_t i = Bracket(t);
  const Node& a = samples_[i];
  if (a.t == t || i + 1 >= samples_.size()) {
    *q_wc = a.q_wc;
    return QueryResult::kOk;
  }
  const Node& b = samples_[i + 1];
  const double s = ToSeconds(t - a.t) / ToSeconds(b.t - a.t);
  *q_wc = a.q_wc.slerp(s, b.q_wc).normalized();
  return QueryResult::kOk;
}

QueryResult OrientationTimeline::RealRotation(Time t,
                                              Eigen::Quaterniond* R_r) const {
  Eigen::Quaterniond q_wc;
  const QueryResult r = CameraToWorld(t, &q_wc);
  if (QuerySucceeded(r)) *R_r = q_wc.conjugate();
  return r;
}

QueryResult OrientationTimeline::AngularVelocity(Time t_cam,
                                                 Eigen::Vector3d* omega) const {
  if (samples_.empty()) return QueryResult::kEmpty;
  const Time t = t_cam - correction_;
  if (t < samples_.front().t) return QueryResult::kBeforeStart;
  if (t > samples_.back().t) {
    if (ToSeconds(t - samples_.back().t) > options_.max_extrapolation_s) {
      return QueryResult::kAfterEnd;
    }
    *omega = samples_.back().omega;
    return QueryResult::kExtrapolated;
  }
  const size_t i = Bracket(t);
  if (i + 1 >= samples_.size()) {
    *omega = samples_[i].omega;
    return QueryResult::kOk;
  }
  const Node& a = samples_[i];
  const Node& b = samples_[i + 1];
  const double s = ToSeconds(t - a.t) / ToSeconds(b.t - a.t);
  *omega = (1.0 - s) * a.omega + s * b.omega;
  return QueryResult::kOk;
}

bool OrientationTimeline::MeanAngularSpeed(Time t0_cam, Time t1_cam,
                                           double* mean) const {
  if (samples_.size() < 2 || t1_cam <= t0_cam) return false;
  const Time t0 = t0_cam - correction_, t1 = t1_cam - correction_;
  auto it = std::lower_bound(
      samples_.begin(), samples_.end(), t0,
      [](const Node& n, const Time& value) { return n.t < value; });
  double integral = 0.0, span = 0.0;
  int used = 0;
  const Node* prev = nullptr;
  for (; it != samples_.end() && it->t <= t1; ++it) {
    if (prev != nullptr) {
      const double dt = ToSeconds(it->t - prev->t);
      integral += 0.5 * dt * (prev->omega.norm() + it->omega.norm());
      span += dt;
    }
    prev = &*it;
    ++used;
  }
  if (used < 2 || span <= 0.0) return false;
  *mean = integral / span;
  return true;
}

void OrientationTimeline::Reset() {
  samples_.clear();
  ++stats_.resets;
}

}  // namespace steadiface

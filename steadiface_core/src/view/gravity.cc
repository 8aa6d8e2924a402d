#include "steadiface_core/view/gravity.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace steadiface {

Status ParseHorizonMode(const std::string& name, HorizonMode* mode) {
  if (name == "off") {
    *mode = HorizonMode::kOff;
  } else if (name == "level") {
    *mode = HorizonMode::kLevel;
  } else if (name == "lock") {
    *mode = HorizonMode::kLock;
  } else {
    return Status::Error("output horizon must be off, level or lock, got '" +
                         name + "'");
  }
  return Status::Ok();
}

const char* HorizonModeName(HorizonMode mode) {
  switch (mode) {
    case HorizonMode::kLevel:
      return "level";
    case HorizonMode::kLock:
      return "lock";
    case HorizonMode::kOff:
      break;
  }
  return "off";
}

Status ValidateHorizonOptions(const HorizonOptions& o) {
  std::ostringstream err;
  auto in = [](double v, double lo, double hi) {
    return std::isfinite(v) && v >= lo && v <= hi;
  };
  if (!in(o.gravity_tolerance, 1e-3, 1.0)) {
    err << "horizon.gravity_tolerance must be in [0.001, 1], got "
        << o.gravity_tolerance;
  } else if (!in(o.time_constant_s, 0.05, 60.0)) {
    err << "horizon.time_constant must be in [0.05, 60] s, got "
        << o.time_constant_s;
  } else if (!in(o.lowpass_hz, 0.01, 10.0)) {
    err << "horizon.lowpass must be in [0.01, 10] Hz, got " << o.lowpass_hz;
  } else if (!in(o.warmup_s, 0.0, 60.0)) {
    err << "horizon.warmup must be in [0, 60] s, got " << o.warmup_s;
  } else if (!in(o.level_tolerance_deg, 0.0, 10.0)) {
    err << "horizon.level_tolerance must be in [0, 10] deg, got " << o.level_tolerance_deg;
  } else if (!in(o.level_weight, 0.0, 1e6) || !in(o.lock_weight, 0.0, 1e6)) {
    err << "horizon.level_weight and lock_weight must be in [0, 1e6], got "
        << o.level_weight << " and " << o.lock_weight;
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

bool GravityEstimator::Add(Time t, const Eigen::Vector3d& a_cam,
                           const OrientationTimeline& timeline) {
  const double norm = a_cam.norm();
  Eigen::Quaterniond q_wc;
  if (!a_cam.allFinite() ||
      std::abs(norm - kStandardGravity) >
          options_.gravity_tolerance * kStandardGravity ||
      !QuerySucceeded(timeline.CameraToWorld(t, &q_wc))) {
    ++rejected_;
    return false;
  }
  const Eigen::Vector3d up = (q_wc * a_cam) / norm;
  double dt = 0.0;
  if (accepted_ == 0) {
    up_ = smooth_ = up;
    smooth_rate_.setZero();
    first_t_ = t;
  } else {
    // First order towards the reading, dt / tau of the way; until tau is
    // filled, the mean of the readings so far (1 / n): gravity is constant
    // in the world frame, so the estimate starts as well as it can and
    // only the gyro's slow drift needs following.
    dt = has_time_ ? std::min(std::max(0.0, ToSeconds(t - last_t_)), 0.1) : 0.0;
    const double k =
        std::min(1.0, std::max(dt / options_.time_constant_s,
                               1.0 / static_cast<double>(accepted_ + 1)));
    up_ = (up_ + k * (up - up_)).normalized();
    if (!valid()) {
      smooth_ = up_;  // warming up: the mean so far, not yet in use
    } else {
      // The second stage (semi-implicit Euler, stable for w dt < 1).
      const double w = 2.0 * M_PI * options_.lowpass_hz;
      smooth_rate_ += (w * w * (up_ - smooth_) - 2.0 * w * smooth_rate_) * dt;
      smooth_ += smooth_rate_ * dt;
    }
  }
  has_time_ = true;
  last_t_ = t;
  ++accepted_;
  return true;
}

void GravityEstimator::Reset() {
  up_ = smooth_ = Eigen::Vector3d(0.0, -1.0, 0.0);
  smooth_rate_.setZero();
  has_time_ = false;
  accepted_ = 0;
}

double HorizonRoll(const Eigen::Vector3d& up_cam) {
  return std::atan2(up_cam.x(), -up_cam.y());
}

}  // namespace steadiface

#include "steadiface_core/common/tracking_lowpass.h"

#include <algorithm>
#include <cmath>

namespace steadiface {

const Eigen::Vector2d& TrackingLowpass::Update(const Eigen::Vector2d& x, double dt) {
  const double wn = 2.0 * M_PI * hz_;
  if (!started_ || !(dt > 0.0)) {
    slow_ = x;
    rate_.setZero();
    smooth_ = x;
    started_ = true;
    return smooth_;
  }
  const double h = std::min(dt, 0.5 / wn);
  const Eigen::Vector2d e = x - slow_;
  rate_ += wn * wn * e * h;
  slow_ += (rate_ + 2.0 * wn * e) * h;
  // The loop's zero passes ~2 wn / w of faster motion: a first-order
  // low-pass at post_ratio x its frequency on top.
  constexpr double post_ratio = 5.0;
  smooth_ += (1.0 - std::exp(-dt * post_ratio * wn)) * (slow_ - smooth_);
  return smooth_;
}

}  // namespace steadiface

namespace steadiface {

const Eigen::Vector2d& SlowMotionFilter::Update(const Eigen::Vector2d& x, double dt) {
  if (!started_ || !(dt > 0.0)) {
    position_ = x;
    velocity_.setZero();
    smooth_ = x;
    started_ = true;
    has_covariance_ = false;
    return smooth_;
  }
  const double wn = 2.0 * M_PI * hz_;
  const double R = 1.0 / dt;  // unit noise density, sampled every dt
  if (!has_covariance_) {
    // The first position is known to R; the velocity is unknown (its
    // prior is 100x what two samples tell).
    P_ << R, 0.0, 0.0, 100.0 * 2.0 * R / (dt * dt);
    has_covariance_ = true;
  }
  // Predict.
  Eigen::Matrix2d F;
  F << 1.0, dt, 0.0, 1.0;
  const double q = std::pow(wn, 4);
  Eigen::Matrix2d Q;
  Q << q * dt * dt * dt / 3.0, q * dt * dt / 2.0, q * dt * dt / 2.0, q * dt;
  P_ = F * P_ * F.transpose() + Q;
  position_ += velocity_ * dt;
  // Update with the position.
  const double S = P_(0, 0) + R;
  const Eigen::Vector2d K = P_.col(0) / S;
  const Eigen::Vector2d innovation = x - position_;
  position_ += K(0) * innovation;
  velocity_ += K(1) * innovation;
  const Eigen::Matrix2d P = P_;
  P_ = P - K * P.row(0);
  // The first-order stage, led by the velocity times its lag on a ramp
  // (for the sampled stage y += (1 - a)(x - y), a = exp(-dt / tau), that lag
  // is dt a / (1 - a), about tau - dt / 2).
  constexpr double post_ratio = 5.0;
  const double a = std::exp(-dt * post_ratio * wn);
  const double lead = dt * a / (1.0 - a);
  smooth_ += (1.0 - a) * (position_ + velocity_ * lead - smooth_);
  return smooth_;
}

}  // namespace steadiface

#include "steadiface_core/tracking_lowpass.h"

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

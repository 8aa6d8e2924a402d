#include "steadiface_core/calibration/gyro_integral.h"

namespace steadiface {

GyroIntegral::GyroIntegral(const std::vector<GyroSample>& samples) {
  if (samples.empty()) return;
  origin_ = samples.front().stamp;
  for (const GyroSample& s : samples) {
    const double t = ToSeconds(s.stamp - origin_);
    if (!t_.empty() && t <= t_.back()) continue;  // strictly increasing
    if (t_.empty()) {
      I_.push_back(Eigen::Vector3d::Zero());
    } else {
      const double h = t - t_.back();
      I_.push_back(I_.back() + 0.5 * h * (w_.back() + s.angular_velocity));
    }
    t_.push_back(t);
    w_.push_back(s.angular_velocity);
  }
}

Eigen::Vector3d GyroIntegral::Rate(double t) const {
  if (empty()) return Eigen::Vector3d::Zero();
  if (t <= t_.front()) return w_.front();
  if (t >= t_.back()) return w_.back();
  const size_t k = static_cast<size_t>(
                       std::upper_bound(t_.begin(), t_.end(), t) - t_.begin()) -
                   1;
  const double a = (t - t_[k]) / (t_[k + 1] - t_[k]);
  return (1 - a) * w_[k] + a * w_[k + 1];
}

}  // namespace steadiface

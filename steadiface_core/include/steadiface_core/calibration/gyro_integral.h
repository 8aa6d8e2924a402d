#pragma once

#include <algorithm>
#include <vector>

#include <Eigen/Core>

#include "steadiface_core/gyro/orientation_timeline.h"

namespace steadiface {

/// The running integral of raw gyro readings, I(t) = int omega dt, on the
/// IMU's clock and in the IMU's axes, with omega linear between samples (so
/// I is piecewise quadratic and dI/dt = omega(t) is continuous). Generic in
/// the query time, for Ceres: the offset and the readout that place a row's
/// time are parameters of the calibration. Times are seconds relative to
/// `origin()`.
class GyroIntegral {
 public:
  /// `samples` in time order (stamps strictly increasing).
  explicit GyroIntegral(const std::vector<GyroSample>& samples);

  bool empty() const { return t_.size() < 2; }
  Time origin() const { return origin_; }
  /// First and last sample times [s since origin].
  double begin() const { return t_.empty() ? 0.0 : t_.front(); }
  double end() const { return t_.empty() ? 0.0 : t_.back(); }
  /// omega at a sample-time-relative t (clamped to the span) [rad/s].
  Eigen::Vector3d Rate(double t) const;

  /// I(t) [rad]; t is clamped to the sampled span.
  template <typename T>
  Eigen::Matrix<T, 3, 1> At(const T& t) const {
    const double ts = Scalar(t);
    size_t k = static_cast<size_t>(std::upper_bound(t_.begin(), t_.end(), ts) -
                                   t_.begin());
    k = std::min(std::max<size_t>(k, 1), t_.size() - 1) - 1;  // [t_k, t_k+1]
    T dt = t - T(t_[k]);
    const double h = t_[k + 1] - t_[k];
    if (ts < t_.front()) dt = T(0.0);
    if (ts > t_.back()) dt = T(h);
    const Eigen::Vector3d slope = (w_[k + 1] - w_[k]) / h;
    Eigen::Matrix<T, 3, 1> out;
    for (int i = 0; i < 3; ++i) {
      out(i) = T(I_[k](i)) + T(w_[k](i)) * dt + T(0.5 * slope(i)) * dt * dt;
    }
    return out;
  }

 private:
  static double Scalar(double v) { return v; }
  template <typename J>
  static double Scalar(const J& v) {
    return v.a;
  }

  Time origin_;
  std::vector<double> t_;
  std::vector<Eigen::Vector3d> w_, I_;
};

}  // namespace steadiface

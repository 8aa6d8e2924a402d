#include "steadiface_core/stabilizer/dynamic_weights.h"

#include <algorithm>
#include <cmath>

namespace steadiface {

double SmoothStep(double x, double lo, double hi) {
  if (!(hi > lo)) return x >= hi ? 1.0 : 0.0;
  const double s = std::min(std::max((x - lo) / (hi - lo), 0.0), 1.0);
  return s * s * (3.0 - 2.0 * s);
}

DynamicWeights::DynamicWeights(const DynamicWeightOptions& options)
    : options_(options) {}

void DynamicWeights::Reset() {
  initialized_ = false;
  history_.clear();
  fit_pose_ = fit_gyro_ = fit_var_ = 1.0;
  presence_ = 0.0;
  state_ = WeightFactors();
}

WeightFactors DynamicWeights::Update(double dt_s, double mean_angular_speed,
                                     const FaceObservation* face,
                                     const Eigen::Vector2d& stabilized_centre,
                                     double stabilized_scale) {
  const DynamicWeightOptions& o = options_;
  const bool has_face = face != nullptr && face->valid;
  WeightFactors f;
  f.mean_angular_speed = mean_angular_speed;
  f.presence_target = has_face ? 1.0 : 0.0;

  // Targets.
  double smooth_target = 1.0;
  if (o.enabled) {
    if (mean_angular_speed >= 0.0) {
      f.gyro_target = o.gyro_still_fit_scale +
                      (1.0 - o.gyro_still_fit_scale) *
                          SmoothStep(mean_angular_speed, o.gyro_still_rad_s,
                                     o.gyro_active_rad_s);
    }
    if (has_face && face->has_pose) {
      const double pose =
          std::max(std::abs(face->yaw), std::abs(face->pitch));
      const double s = SmoothStep(pose, o.pose_low_rad, o.pose_high_rad);
      f.pose_target = 1.0 - (1.0 - o.pose_min_fit_scale) * s;
      smooth_target = 1.0 + o.pose_smoothness_boost * s;
    }
    if (has_face) {
      f.variation_target = VariationTarget(stabilized_centre, stabilized_scale, &f);
    } else {
      history_.clear();
    }
  } else if (!has_face) {
    history_.clear();
  }

  // First-order approach to the targets.
  double a = 1.0;
  if (initialized_ && dt_s > 0.0 && o.fade_time_s > 0.0) {
    a = 1.0 - std::exp(-dt_s / o.fade_time_s);
  }
  auto approach = [a](double cur, double target) {
    return cur + a * (target - cur);
  };
  if (!initialized_) {
    // The stream's first frame: there is no previous virtual camera to jump
    // from (it starts at the real one with H = C), so w_f starts at its
    // target; every later appearance or loss fades.
    presence_ = f.presence_target;
    fit_gyro_ = f.gyro_target;
    fit_pose_ = f.pose_target;
    fit_var_ = f.variation_target;
    state_.smoothness = smooth_target;
    initialized_ = true;
  } else {
    presence_ = approach(presence_, f.presence_target);
    fit_gyro_ = approach(fit_gyro_, f.gyro_target);
    fit_pose_ = approach(fit_pose_, f.pose_target);
    fit_var_ = approach(fit_var_, f.variation_target);
    state_.smoothness = approach(state_.smoothness, smooth_target);
  }
  f.fit = presence_ * fit_gyro_ * fit_pose_ * fit_var_;
  f.smoothness = state_.smoothness;
  return f;
}

double DynamicWeights::VariationTarget(const Eigen::Vector2d& stabilized_centre,
                                       double stabilized_scale, WeightFactors* out) {
  // The landmark-variation factor: RMS second differences of the
  // gyro-compensated centre and of the relative scale over the window.
  const DynamicWeightOptions& o = options_;
  WeightFactors& f = *out;
  history_.emplace_back(stabilized_centre.x(), stabilized_centre.y(),
                        stabilized_scale);
  while (static_cast<int>(history_.size()) > o.variation_window) {
    history_.pop_front();
  }
  if (history_.size() >= 3) {
    double c2 = 0.0, s2 = 0.0;
    int n = 0;
    for (size_t i = 2; i < history_.size(); ++i) {
      const Eigen::Vector3d d2 =
          history_[i] - 2.0 * history_[i - 1] + history_[i - 2];
      c2 += d2.head<2>().squaredNorm();
      const double sc = std::max(history_[i - 1].z(), 1e-6);
      s2 += (d2.z() / sc) * (d2.z() / sc);
      ++n;
    }
    f.centre_variation = std::sqrt(c2 / n);
    f.scale_variation = std::sqrt(s2 / n);
    const double v = std::max(
        SmoothStep(f.centre_variation, o.centre_variation_low,
                   o.centre_variation_high),
        SmoothStep(f.scale_variation, o.scale_variation_low,
                   o.scale_variation_high));
    return 1.0 - (1.0 - o.variation_min_fit_scale) * v;
  }
  return f.variation_target;
}

}  // namespace steadiface

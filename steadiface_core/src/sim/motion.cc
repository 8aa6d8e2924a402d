#include "steadiface_core/sim/motion.h"

#include <cmath>
#include <random>

#include "steadiface_core/common/so3.h"

namespace steadiface {
namespace sim {

BandLimitedNoise::BandLimitedNoise(uint64_t seed, double f_lo, double f_hi,
                                   double rms, int n) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  // Equal amplitudes: each sinusoid has RMS amp/sqrt(2); n of them add in
  // power.
  const double amp = rms * std::sqrt(2.0 / std::max(1, n));
  for (int i = 0; i < n; ++i) {
    Component c;
    c.freq = f_lo + (f_hi - f_lo) * (i + u01(rng)) / n;
    c.amp = amp;
    c.phase = Eigen::Vector3d(u01(rng), u01(rng), u01(rng)) * 2.0 * M_PI;
    components_.push_back(c);
  }
}

Eigen::Vector3d BandLimitedNoise::Value(double t) const {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (const auto& c : components_) {
    for (int k = 0; k < 3; ++k) {
      v[k] += c.amp * std::sin(2.0 * M_PI * c.freq * t + c.phase[k]);
    }
  }
  return v;
}

Eigen::Vector3d BandLimitedNoise::Derivative(double t) const {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  for (const auto& c : components_) {
    const double w = 2.0 * M_PI * c.freq;
    for (int k = 0; k < 3; ++k) {
      v[k] += c.amp * w * std::cos(w * t + c.phase[k]);
    }
  }
  return v;
}

CameraMotion::CameraMotion(const CameraMotionOptions& o)
    : options_(o),
      shake_(o.seed, o.shake_lo_hz, o.shake_hi_hz, o.shake_rms_rad),
      translation_(o.seed + 1000, 0.3, 3.0, o.translation_rms_m, 12) {}

double CameraMotion::PanAngle(double t) const {
  // The pan rate ramps in smoothly (smoothstep) over [pan_start_s,
  // pan_start_s + pan_ramp_s]; the angle is its exact integral.
  const double t0 = options_.pan_start_s, T = std::max(1e-9, options_.pan_ramp_s);
  if (t <= t0) return 0.0;
  const double u = std::min(1.0, (t - t0) / T);
  double a = T * (u * u * u - 0.5 * u * u * u * u);
  if (t > t0 + T) a += t - (t0 + T);
  return options_.pan_rate * a;
}

Eigen::Quaterniond CameraMotion::Orientation(double t) const {
  const double roll = options_.roll_amplitude_rad * std::sin(2.0 * M_PI * options_.roll_hz * t);
  return ExpSO3(Eigen::Vector3d(0.0, PanAngle(t), 0.0)) * ExpSO3(Eigen::Vector3d(0.0, 0.0, roll)) *
         ExpSO3(shake_.Value(t));
}

Eigen::Vector3d CameraMotion::Position(double t) const {
  return translation_.Value(t);
}

Eigen::Vector3d CameraMotion::AngularVelocity(double t) const {
  const double h = 1e-6;
  return LogSO3(Orientation(t - h).conjugate() * Orientation(t + h)) /
         (2.0 * h);
}

HeadMotion::HeadMotion(const HeadMotionOptions& o)
    : options_(o), jitter_(o.seed, 2.0, 8.0, o.jitter_rms_m, 12) {}

double HeadMotion::Yaw(double t) const {
  return options_.yaw_amplitude_rad * std::sin(2 * M_PI * options_.yaw_hz * t);
}

double HeadMotion::Pitch(double t) const {
  return options_.pitch_amplitude_rad *
         std::sin(2 * M_PI * options_.pitch_hz * t + 1.0);
}

Eigen::Quaterniond HeadMotion::Orientation(double t) const {
  return Eigen::Quaterniond(Eigen::AngleAxisd(Yaw(t), Eigen::Vector3d::UnitY())) *
         Eigen::Quaterniond(Eigen::AngleAxisd(Pitch(t), Eigen::Vector3d::UnitX()));
}

Eigen::Vector3d HeadMotion::Position(double t) const {
  const HeadMotionOptions& o = options_;
  const double w = 2 * M_PI * o.bob_hz;
  Eigen::Vector3d p(o.sway_amplitude_m * std::sin(0.5 * w * t),
                    o.bob_amplitude_m * std::sin(w * t),
                    o.distance_m +
                        o.lean_amplitude_m * std::sin(2 * M_PI * o.lean_hz * t));
  if (o.drift_amplitude_m != 0.0) {
    const double d = 2 * M_PI * o.drift_hz * t;
    p.x() += o.drift_amplitude_m * std::sin(d);
    p.y() += 0.5 * o.drift_amplitude_m * std::sin(0.7 * d + 0.5);
  }
  if (o.walk_speed_m_s != 0.0 || o.walk_start_x_m != 0.0) {
    p.x() += o.walk_start_x_m + o.walk_speed_m_s * t;
  }
  return p + jitter_.Value(t);
}

}  // namespace sim
}  // namespace steadiface

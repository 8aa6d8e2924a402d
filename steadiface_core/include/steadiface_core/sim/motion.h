#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace steadiface {
namespace sim {

/// Band-limited random motion: a sum of sinusoids with frequencies spread
/// uniformly over [f_lo, f_hi], random phases and equal amplitudes, scaled to
/// the requested RMS per axis. Deterministic given the seed.
class BandLimitedNoise {
 public:
  BandLimitedNoise() = default;
  BandLimitedNoise(uint64_t seed, double f_lo_hz, double f_hi_hz,
                   double rms_per_axis, int components = 24);
  Eigen::Vector3d Value(double t) const;
  Eigen::Vector3d Derivative(double t) const;

 private:
  struct Component {
    double freq, amp;
    Eigen::Vector3d phase;
  };
  std::vector<Component> components_;
};

/// Camera motion: intentional pan (constant rate about the camera's y axis
/// over time, rad/s) times hand shake (band-limited rotation vector), plus a
/// small hand translation. q_wc(t) = Exp(pan t e_y) Exp(shake(t)).
struct CameraMotionOptions {
  /// Pan rate about the vertical axis [rad/s], reached smoothly over
  /// [pan_start_s, pan_start_s + pan_ramp_s] [s] (a person starting a pan).
  double pan_rate = 0.0;
  double pan_start_s = 0.3;
  double pan_ramp_s = 2.0;
  /// Hand-shake RMS angle per axis [rad].
  double shake_rms_rad = 0.006;
  /// Hand-shake band [Hz].
  double shake_lo_hz = 1.0, shake_hi_hz = 12.0;
  /// Hand translation RMS per axis [m], band 0.3-3 Hz.
  double translation_rms_m = 0.004;
  /// A slow roll about the optical axis: amplitude [rad] and frequency
  /// [Hz] of roll(t) = amplitude sin(2 pi hz t) (the horizon tilting).
  double roll_amplitude_rad = 0.0;
  double roll_hz = 0.2;
  uint64_t seed = 1;
};

class CameraMotion {
 public:
  explicit CameraMotion(const CameraMotionOptions& options);
  /// Camera-to-world rotation.
  Eigen::Quaterniond Orientation(double t) const;
  /// Camera position in the world [m].
  Eigen::Vector3d Position(double t) const;
  /// Intentional pan angle at t [rad].
  double PanAngle(double t) const;
  /// Body-frame angular velocity [rad/s] (exact derivative by a tiny
  /// central difference of the analytic orientation).
  Eigen::Vector3d AngularVelocity(double t) const;

 private:
  CameraMotionOptions options_;
  BandLimitedNoise shake_, translation_;
};

/// Head motion relative to the body carrying the camera: base position
/// `distance_m` in front of the camera's start, plus a bob of the head on
/// the body (vertical and lateral), turning (yaw) and nodding (pitch), and
/// leaning in/out. Walking motion that moves camera and head together is
/// the sequence's (body) business.
struct HeadMotionOptions {
  double distance_m = 0.45;
  /// Vertical bob amplitude [m] at bob_hz, lateral sway at bob_hz / 2.
  double bob_amplitude_m = 0.004;
  double sway_amplitude_m = 0.003;
  double bob_hz = 1.8;
  /// Yaw and pitch oscillation amplitudes [rad] and their frequencies [Hz].
  double yaw_amplitude_rad = 0.12;
  double yaw_hz = 0.25;
  double pitch_amplitude_rad = 0.06;
  double pitch_hz = 0.4;
  /// Leaning in/out amplitude [m] and frequency [Hz].
  double lean_amplitude_m = 0.02;
  double lean_hz = 0.15;
  /// Extra high-frequency head jitter RMS [m] (band 2-8 Hz).
  double jitter_rms_m = 0.0015;
  /// Slow drift of the head against the scene: lateral amplitude [m] at
  /// drift_hz [Hz], and half that vertically at 0.7 drift_hz (a person
  /// shifting their weight, leaning aside). 0 = none.
  double drift_amplitude_m = 0.0;
  double drift_hz = 0.15;
  /// Walking across the view: the head starts walk_start_x_m to the side
  /// [m] and moves sideways at walk_speed_m_s [m/s]. 0 = standing.
  double walk_start_x_m = 0.0;
  double walk_speed_m_s = 0.0;
  uint64_t seed = 2;
};

class HeadMotion {
 public:
  explicit HeadMotion(const HeadMotionOptions& options);
  /// Head-to-world rotation (facing the camera: the head's z points back at
  /// the camera, i.e. head frame = world frame rotated by pi about y is NOT
  /// used; the face model's -z points towards the camera).
  Eigen::Quaterniond Orientation(double t) const;
  /// Head origin in the world [m].
  Eigen::Vector3d Position(double t) const;
  double Yaw(double t) const;
  double Pitch(double t) const;

 private:
  HeadMotionOptions options_;
  BandLimitedNoise jitter_;
};

}  // namespace sim
}  // namespace steadiface

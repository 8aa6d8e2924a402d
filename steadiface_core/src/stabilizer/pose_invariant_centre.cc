#include "steadiface_core/stabilizer/pose_invariant_centre.h"

#include <algorithm>
#include <cmath>

#include "steadiface_core/stabilizer/dynamic_weights.h"

namespace steadiface {
namespace {

// The one-euro filter's cut-off of the speed estimate [Hz] (its authors'
// default).
constexpr double kSpeedCutoffHz = 1.0;

// A first-order low-pass's gain for a step of `dt` at cut-off `hz`.
double Gain(double dt, double hz) { return 1.0 - std::exp(-2.0 * M_PI * hz * dt); }

// The same for time constant `tau` [s]; 1 (no smoothing) where tau <= 0.
double DecayGain(double dt, double tau) { return tau > 0.0 ? 1.0 - std::exp(-dt / tau) : 1.0; }

}  // namespace

void PoseInvariantCentre::FilterYaw(double yaw, double dt) {
  const double tau = options_.pose_yaw_time_constant_s;
  if (!has_yaw_ || !(dt > 0.0) || tau <= 0.0) {
    yaw_ = yaw;
    yaw_speed_ = 0.0;
    return;
  }
  // One-euro filter (Casiez, Roussel and Vogel 2012): the speed, low-passed,
  // opens the yaw's low-pass above a floor, so that a slow or still head's
  // PnP noise is smoothed and a fast turn is not followed late.
  const double h = std::min(dt, 1.0);
  yaw_speed_ += Gain(h, kSpeedCutoffHz) * ((yaw - yaw_) / h - yaw_speed_);
  const double excess = std::max(0.0, std::abs(yaw_speed_) - options_.pose_yaw_speed_floor_rad_s);
  const double cutoff_hz = 1.0 / (2.0 * M_PI * tau) + options_.pose_yaw_speed_gain * excess;
  yaw_ += Gain(h, cutoff_hz) * (yaw - yaw_);
}

double PoseInvariantCentre::FilterNod(double pitch, double dt) {
  if (!has_pitch_ || !(dt > 0.0)) {
    pitch_ = pitch_mean_ = pitch;
    has_pitch_ = true;
    return 0.0;
  }
  const double h = std::min(dt, 1.0);
  pitch_ += DecayGain(h, options_.pose_yaw_time_constant_s) * (pitch - pitch_);
  pitch_mean_ += DecayGain(h, options_.pose_nod_time_constant_s) * (pitch - pitch_mean_);
  return pitch_ - pitch_mean_;
}

FaceObservation PoseInvariantCentre::Apply(const FaceObservation& face, double dt) {
  last_shift_ = last_nod_shift_ = 0.0;
  if (options_.pose_pivot_depth <= 0.0 || !face.valid || !face.has_pose ||
      !std::isfinite(face.yaw) || !(face.scale > 0.0)) {
    return face;
  }
  FilterYaw(face.yaw, dt);
  has_yaw_ = true;
  // The landmarks' centre sits at -d sin(yaw) (x right) from where it would
  // be facing the camera: moved back by +d sin(yaw).
  last_shift_ = options_.pose_pivot_depth * face.scale * std::sin(yaw_);
  // The nod moves them down by d sin(pitch) (y down): moved back by a
  // share of it, fading out between pose_nod_max_yaw and twice it.
  if (options_.pose_nod_gain > 0.0 && std::isfinite(face.pitch)) {
    const double nod = FilterNod(face.pitch, dt);
    const double lo = options_.pose_nod_max_yaw_rad;
    const double keep = 1.0 - SmoothStep(std::abs(yaw_), lo, 2.0 * lo);
    last_nod_shift_ = -keep * options_.pose_nod_gain * options_.pose_pivot_depth * face.scale *
                      std::sin(nod);
  }
  FaceObservation out = face;
  ShiftFace(Eigen::Vector2d(last_shift_, last_nod_shift_), &out);
  return out;
}

}  // namespace steadiface

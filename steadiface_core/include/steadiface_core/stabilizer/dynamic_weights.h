#pragma once

#include <deque>

#include <Eigen/Core>

#include "steadiface_core/face/face_observation.h"
#include "steadiface_core/stabilizer/stabilizer_options.h"

namespace steadiface {

/// The factors dynamic adjustment applies to the base weights this frame.
struct WeightFactors {
  /// Multiplies w_f (includes the face-presence fade) [-].
  double fit = 0.0;
  /// Multiplies the smoothness weights w_r,C0/C1 and w_t,C0/C1 [-].
  double smoothness = 1.0;
  /// The targets each factor is fading towards, for diagnostics.
  double gyro_target = 1.0;
  double pose_target = 1.0;
  double variation_target = 1.0;
  double presence_target = 0.0;
  /// Measured inputs.
  double mean_angular_speed = 0.0;    ///< [rad/s]
  double centre_variation = 0.0;      ///< [normalized]
  double scale_variation = 0.0;       ///< [-]
};

/// Paper §4.4, dynamic optimization weight adjustment:
///  1. mean |omega| over a window scales w_f (still camera -> still virtual
///     camera);
///  2. large head yaw/pitch lowers w_f and raises the smoothness weights;
///  3. large variation of the landmark centre (gyro-compensated) or scale
///     lowers w_f;
///  4. no face: w_f fades to 0; a face fades it back in.
/// Each factor approaches its target through a first-order filter with time
/// constant fade_time_s (exact exponential for the frame's dt), so the
/// weights are continuous in time.
class DynamicWeights {
 public:
  explicit DynamicWeights(const DynamicWeightOptions& options);

  /// `dt_s` since the previous frame (on the first frame, and for dt_s <= 0,
  /// the factors jump straight to their targets); `mean_angular_speed` over the window
  /// (negative = unknown, counts as active); `face` may be null;
  /// `stabilized_centre` and `stabilized_scale` are C and the face scale as
  /// a world-fixed camera sees them (camera shake removed: each landmark
  /// through the real rotation of its own row, so rolling-shutter skew is
  /// not counted as landmark noise) [normalized], meaningful when the face is
  /// valid.
  WeightFactors Update(double dt_s, double mean_angular_speed,
                       const FaceObservation* face,
                       const Eigen::Vector2d& stabilized_centre,
                       double stabilized_scale);

  void Reset();
  void set_options(const DynamicWeightOptions& options) { options_ = options; }

 private:
  // The landmark-variation target (1 while fewer than 3 frames are in the
  // window); the window's figures into *f.
  double VariationTarget(const Eigen::Vector2d& stabilized_centre, double stabilized_scale,
                         WeightFactors* f);
  DynamicWeightOptions options_;
  bool initialized_ = false;
  WeightFactors state_;
  double fit_pose_ = 1.0, fit_gyro_ = 1.0, fit_var_ = 1.0, presence_ = 0.0;
  std::deque<Eigen::Vector3d> history_;  // (centre x, centre y, scale)
};

/// 0 below lo, 1 above hi, C1-smooth in between.
double SmoothStep(double x, double lo, double hi);

}  // namespace steadiface

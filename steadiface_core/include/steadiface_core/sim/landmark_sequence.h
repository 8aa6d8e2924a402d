#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/camera/rolling_shutter.h"
#include "steadiface_core/face/face_observation.h"
#include "steadiface_core/gyro/orientation_timeline.h"
#include "steadiface_core/sim/motion.h"

namespace steadiface {
namespace sim {

/// Geometry-only sequence: the landmarks a perfect detector would see (plus
/// optional pixel noise), the gyro, and exact ground truth. No pixels are
/// rendered, so it is fast enough for unit tests of the stabilizer.
struct LandmarkSequenceOptions {
  CameraMotionOptions camera;
  HeadMotionOptions head;
  /// Walking body motion shared by the camera (held in hand) and the head:
  /// vertical bob and lateral sway [m] at bob_hz (sway at half of it). It
  /// moves both together, so it shifts neither relative to the other.
  double body_bob_m = 0.02;
  double body_sway_m = 0.01;
  double body_bob_hz = 1.8;
  double fps = 30.0;
  double duration_s = 6.0;
  /// Rolling-shutter timing of the simulated camera.
  RollingShutterOptions shutter;
  /// Gyro rate [Hz] and white noise [rad/s, per axis].
  double gyro_rate_hz = 200.0;
  double gyro_noise = 0.0;
  /// Landmark noise [px, per axis].
  double landmark_noise_px = 0.0;
  /// The head turns about a centre this far behind its eyes [m] (a real
  /// head's skull; 0: about the eyes).
  double pivot_depth_m = 0.09;
  /// Frames in [face_lost_from, face_lost_to) have no face observation.
  int face_lost_from = -1, face_lost_to = -1;
  uint64_t seed = 3;
};

struct LandmarkFrame {
  Time stamp;
  FaceObservation observed;  ///< what the tracker would report
  /// Noise-free landmarks [normalized] and their rows [px].
  std::vector<Eigen::Vector2d> true_landmarks;
  std::vector<double> true_rows;
  /// True head centre: the mean of the noise-free landmarks as they would
  /// be with the head facing forward (pose-invariant) [normalized].
  Eigen::Vector2d true_centre;
  /// True camera-to-world orientation at the middle row.
  Eigen::Quaterniond q_wc_mid;
};

class LandmarkSequence {
 public:
  LandmarkSequence(const CameraModel& model,
                   const LandmarkSequenceOptions& options);

  const std::vector<LandmarkFrame>& frames() const { return frames_; }
  const std::vector<GyroSample>& gyro() const { return gyro_; }
  const RowTiming& timing() const { return timing_; }

  /// Where a world direction at infinity appears in frame `i` (normalized,
  /// real, with its own row), iterated over the rolling shutter.
  bool BackgroundPoint(int i, const Eigen::Vector3d& direction,
                       Eigen::Vector2d* normalized, double* row) const;

 private:
  CameraModel model_;
  LandmarkSequenceOptions options_;
  RowTiming timing_;
  CameraMotion camera_;
  HeadMotion head_;
  std::vector<LandmarkFrame> frames_;
  std::vector<GyroSample> gyro_;

  Eigen::Vector3d Body(double t) const;
  // A head point (the generic face's frame) in the image at its own row,
  // turned by the head's pose or facing forward [px].
  Eigen::Vector2d Project(Time stamp, const Eigen::Vector3d& X_head, bool turned) const;
};

}  // namespace sim
}  // namespace steadiface

#include "steadiface_core/sim/landmark_sequence.h"

#include <cmath>
#include <random>

#include "steadiface_core/face/generic_face.h"

namespace steadiface {
namespace sim {

LandmarkSequence::LandmarkSequence(const CameraModel& model,
                                   const LandmarkSequenceOptions& options)
    : model_(model),
      options_(options),
      timing_(options.shutter, model.intrinsics().height),
      camera_(options.camera),
      head_(options.head) {
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  const CameraIntrinsics& k = model.intrinsics();
  // Gyro covers the whole sequence plus the last frame's readout.
  const double t_end = options.duration_s + options.shutter.readout_time_s + 0.05;
  const int n_gyro = static_cast<int>(t_end * options.gyro_rate_hz) + 1;
  for (int i = 0; i < n_gyro; ++i) {
    const double t = i / options.gyro_rate_hz;
    Eigen::Vector3d w = camera_.AngularVelocity(t);
    if (options.gyro_noise > 0) {
      w += options.gyro_noise * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    }
    gyro_.push_back({Time(FromSeconds(t)), w});
  }
  const auto& face = GenericFace68();
  const int n_frames = static_cast<int>(options.duration_s * options.fps);
  for (int f = 0; f < n_frames; ++f) {
    LandmarkFrame fr;
    fr.stamp = Time(FromSeconds(0.05 + f / options.fps));
    const double t_mid = ToSeconds(timing_.RowTime(fr.stamp, 0.5 * (k.height - 1)));
    fr.q_wc_mid = camera_.Orientation(t_mid);
    fr.true_centre.setZero();
    for (const Eigen::Vector3d& X_head : face) {
      Eigen::Vector2d px = Project(fr.stamp, X_head, true);
      fr.true_landmarks.push_back(model.PixelToNormalized(px));
      fr.true_rows.push_back(px.y());
      // The pose-invariant head: the landmarks as they would be seen with
      // the head facing forward.
      fr.true_centre += model.PixelToNormalized(Project(fr.stamp, X_head, false));
      Eigen::Vector2d noisy = px;
      if (options.landmark_noise_px > 0) {
        noisy += options.landmark_noise_px * Eigen::Vector2d(n01(rng), n01(rng));
      }
      fr.observed.landmarks.push_back(model.PixelToNormalized(noisy));
      fr.observed.landmark_rows.push_back(noisy.y());
    }
    fr.true_centre /= static_cast<double>(face.size());
    const bool lost = f >= options.face_lost_from && f < options.face_lost_to;
    fr.observed.valid = !lost;
    if (lost) {
      fr.observed.landmarks.clear();
      fr.observed.landmark_rows.clear();
    }
    fr.observed.confidence = lost ? 0.0 : 0.95;
    fr.observed.has_pose = !lost;
    fr.observed.yaw = head_.Yaw(t_mid);
    fr.observed.pitch = head_.Pitch(t_mid);
    ComputeCentreAndScale(&fr.observed);
    frames_.push_back(std::move(fr));
  }
}

Eigen::Vector2d LandmarkSequence::Project(Time stamp, const Eigen::Vector3d& X_head,
                                          bool turned) const {
  // The head turns about its skull's centre, pivot_depth_m behind the eyes
  // (as the simulator's relief head does); at its own row.
  const CameraIntrinsics& k = model_.intrinsics();
  const Eigen::Vector3d pivot(0.0, 0.0, options_.pivot_depth_m);
  double y = 0.5 * (k.height - 1);
  Eigen::Vector2d px;
  for (int it = 0; it < 8; ++it) {
    const double t = ToSeconds(timing_.RowTime(stamp, y));
    const Eigen::Quaterniond R = turned ? head_.Orientation(t) : Eigen::Quaterniond::Identity();
    const Eigen::Vector3d X_w = R * (X_head - pivot) + pivot + head_.Position(t) + Body(t);
    const Eigen::Vector3d X_c =
        camera_.Orientation(t).conjugate() * (X_w - camera_.Position(t) - Body(t));
    px = Eigen::Vector2d(k.fx * X_c.x() / X_c.z() + k.cx, k.fy * X_c.y() / X_c.z() + k.cy);
    y = px.y();
  }
  return px;
}

Eigen::Vector3d LandmarkSequence::Body(double t) const {
  const double w = 2.0 * M_PI * options_.body_bob_hz;
  return Eigen::Vector3d(options_.body_sway_m * std::sin(0.5 * w * t),
                         options_.body_bob_m * std::sin(w * t), 0.0);
}

bool LandmarkSequence::BackgroundPoint(int i, const Eigen::Vector3d& d,
                                       Eigen::Vector2d* normalized,
                                       double* row) const {
  const CameraIntrinsics& k = model_.intrinsics();
  double y = 0.5 * (k.height - 1);
  Eigen::Vector2d px;
  for (int it = 0; it < 8; ++it) {
    const double t = ToSeconds(timing_.RowTime(frames_[i].stamp, y));
    const Eigen::Vector3d c = camera_.Orientation(t).conjugate() * d;
    if (c.z() <= 1e-6) return false;
    px = Eigen::Vector2d(k.fx * c.x() / c.z() + k.cx, k.fy * c.y() / c.z() + k.cy);
    y = px.y();
  }
  *normalized = model_.PixelToNormalized(px);
  *row = px.y();
  return true;
}

}  // namespace sim
}  // namespace steadiface

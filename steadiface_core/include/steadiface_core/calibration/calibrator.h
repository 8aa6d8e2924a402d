#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/camera/rolling_shutter.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/common/time.h"
#include "steadiface_core/gyro/orientation_timeline.h"

namespace steadiface {

class GyroIntegral;

/// Options of the offline camera-IMU calibration (issue 16).
struct CalibratorOptions {
  /// Width of the grey copy features are tracked on [px].
  int track_width = 640;
  /// Features detected per frame and tracked into the next [count].
  int max_features = 120;
  /// Forward-backward KLT disagreement allowed, in the tracking image [px].
  double max_fb_error_px = 0.5;
  /// Coarse clock-offset search around the initial offset: +- range in
  /// steps (cross-correlation of angular speeds) [s].
  double coarse_range_s = 0.5;
  double coarse_step_s = 0.001;
  /// Estimate the rolling-shutter readout (else keep the initial one).
  bool estimate_readout = true;
  /// Estimate a constant gyro bias (else assume none).
  bool estimate_bias = true;
  /// Refusals: the recording must last this long [s] ...
  double min_duration_s = 1.0;
  /// ... with this many frame pairs that have enough tracks [count] ...
  int min_pairs = 20;
  /// ... each with at least this many tracks [count] ...
  int min_tracks = 15;
  /// ... and this mean angular speed of the gyro [rad/s].
  double min_angular_speed = 0.05;
  /// A parameter whose 1-sigma exceeds this is "not determined" [s, s].
  double max_offset_sigma_s = 0.002;
  double max_readout_sigma_s = 0.003;
  /// Robust loss scale of the reprojection residuals (Cauchy) [px].
  double loss_scale_px = 1.0;
};

Status ValidateCalibratorOptions(const CalibratorOptions& options);

/// What the calibration found. Each estimate comes with its 1-sigma (Ceres
/// covariance, scaled by the residuals' spread).
struct CalibrationResult {
  /// IMU -> camera rotation (omega_cam = R_cam_imu * omega_imu), its
  /// uncertainty [deg], the nearest signed axis permutation and the angle
  /// between them [deg].
  Eigen::Quaterniond R_cam_imu = Eigen::Quaterniond::Identity();
  double rotation_sigma_deg = 0.0;
  Eigen::Quaterniond nearest_permutation = Eigen::Quaterniond::Identity();
  double misalignment_deg = 0.0;
  /// imu/time_offset: added to IMU stamps to reach the camera clock [s].
  double time_offset_s = 0.0, time_offset_sigma_s = 0.0;
  /// Coarse offset from the angular-speed cross-correlation [s].
  double coarse_offset_s = 0.0;
  /// Rolling-shutter readout [s]; whether it was determined.
  double readout_s = 0.0, readout_sigma_s = 0.0;
  bool readout_determined = false;
  /// Gyro bias in IMU axes [rad/s].
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d bias_sigma = Eigen::Vector3d::Zero();
  /// Median reprojection residual of the tracks with the initial settings
  /// and with the estimate [px].
  double residual_before_px = 0.0, residual_after_px = 0.0;
  int pairs = 0, tracks = 0;
  double duration_s = 0.0, mean_angular_speed = 0.0;
  std::string solver_report;
  /// Angular speed per frame pair from the video (tracks) and from the gyro
  /// before and after the estimate, for plots [s since the first frame,
  /// rad/s].
  std::vector<double> plot_t, plot_video, plot_gyro_before, plot_gyro_after;
};

/// Calibrates a camera-IMU pair from a recording with some hand shake: the
/// IMU->camera rotation, the clock offset, the rolling-shutter readout and a
/// gyro bias. Background features are tracked between consecutive frames
/// (KLT, forward-backward checked); then
///  1. the clock offset is found coarsely by cross-correlating the angular
///     speed seen in the video (the rotation between frames, from the
///     tracks) with the gyro's |omega| (which does not depend on the
///     mounting), over +-coarse_range_s;
///  2. the rotation is solved in closed form (Wahba/Kabsch) between the
///     video's and the gyro's angular velocities;
///  3. Ceres refines all four by minimizing the tracks' reprojection error
///     under the gyro-predicted rotation between the two rows' times (Cauchy
///     loss; a second pass drops tracks beyond 3 px), and its covariance
///     gives each parameter's uncertainty.
/// Refuses (Status error, nothing estimated) when the data cannot
/// determine the result: too short, no IMU over the video, too few
/// trackable features (dark or textureless video), too little rotation, or
/// an undetermined offset or rotation. Not thread-safe.
class Calibrator {
 public:
  /// The initial settings (what is configured today) are the starting
  /// point of the readout and the centre of the offset search, and the
  /// "before" of the residuals; the rotation is estimated from scratch.
  static Status Create(const CameraIntrinsics& intrinsics,
                       const RollingShutterOptions& initial_shutter,
                       const Eigen::Quaterniond& initial_R_cam_imu,
                       double initial_time_offset_s,
                       const CalibratorOptions& options,
                       std::unique_ptr<Calibrator>* out);

  /// Raw gyro samples (IMU clock, IMU axes), in any order.
  void AddGyro(const GyroSample& sample);
  /// One frame (8-bit, 1-4 channels, the intrinsics' size), in time order.
  Status AddFrame(const cv::Mat& image, Time stamp);
  int frames() const { return frames_; }

  /// Runs the estimation over everything added.
  Status Solve(CalibrationResult* result);

 private:
  Calibrator(const CameraIntrinsics& intrinsics,
             const RollingShutterOptions& shutter, const Eigen::Quaterniond& R,
             double offset, const CalibratorOptions& options);
  struct Pair {
    Time a, b;
    std::vector<Eigen::Vector3d> ray_a;  // undistorted, z = 1
    std::vector<Eigen::Vector2d> px_b;   // undistorted pixels
    std::vector<double> row_a, row_b;    // raw rows
  };

  // Solve's checks: enough video and IMU data; the gyro covers the video
  // [s since the gyro origin], enough pairs have enough tracks (into *good,
  // *tracks), the camera turned enough (res->mean_angular_speed); then,
  // after the solve, that the clock offset and the rotation are determined.
  Status CheckLength(double duration_s) const;
  Status CheckRecording(const GyroIntegral& g, double video_begin, double video_end,
                        std::vector<const Pair*>* good, size_t* tracks,
                        CalibrationResult* res) const;
  Status Determined(const CalibrationResult& res, bool have_cov) const;

  const CameraIntrinsics k_;
  const RollingShutterOptions shutter_;
  const Eigen::Quaterniond initial_R_;
  const double initial_offset_s_;
  const CalibratorOptions options_;
  std::vector<GyroSample> gyro_;
  std::vector<Pair> pairs_;
  cv::Mat prev_grey_;
  Time prev_stamp_;
  Time first_stamp_, last_stamp_;
  int frames_ = 0;
  double scale_ = 1.0;
};

}  // namespace steadiface

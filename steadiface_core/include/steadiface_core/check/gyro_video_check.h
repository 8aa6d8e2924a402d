#pragma once

#include <array>
#include <deque>
#include <memory>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_intrinsics.h"
#include "steadiface_core/camera/rolling_shutter.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/common/time.h"
#include "steadiface_core/gyro/orientation_timeline.h"

namespace steadiface {

/// Options of GyroVideoCheck.
struct GyroVideoCheckOptions {
  /// Run the check at all.
  bool enabled = true;
  /// Check one frame pair in this many (1 = every pair) [count]: the cost
  /// (~2 ms per checked pair at 720p on one core) spread over frames.
  int stride = 5;
  /// Width of the grey copy the features are tracked on [px].
  int track_width = 320;
  /// Background features tracked between consecutive frames [count].
  int max_features = 60;
  /// Forward-backward KLT disagreement allowed, in the tracking image [px].
  double max_fb_error_px = 0.5;
  /// Evidence window [s].
  double window_s = 4.0;
  /// Clock offsets searched around the configured imu/time_offset:
  /// +-offset_range_s in steps of offset_step_s [s].
  double offset_range_s = 0.06;
  double offset_step_s = 0.005;
  /// Frame pairs in the window before judging [count].
  int min_pairs = 15;
  /// Mean image motion needed to judge (median feature flow per frame pair,
  /// averaged over the window) [px].
  double min_motion_px = 1.0;
  /// Another IMU mounting "explains the video better" when its residual is
  /// below this fraction of the configured mounting's [-].
  double better_mounting_ratio = 0.6;
  /// Offset disagreement that raises the warning [s].
  double offset_warn_s = 0.005;
  /// Apply the estimate: the pipeline's timeline follows the check's clock
  /// offset correction (only while the check judges and the configured
  /// rotation agrees with the video), at most apply_rate_s_per_s fast.
  bool apply_offset = true;
  /// How fast the applied correction may move [s per s of stream time]:
  /// slow enough that a change never shows as a jump in the output.
  double apply_rate_s_per_s = 0.005;
};

Status ValidateGyroVideoCheckOptions(const GyroVideoCheckOptions& o);

/// What the check concluded over its window.
struct GyroVideoCheckResult {
  /// Enough frame pairs and image motion in the window to judge.
  bool judged = false;
  int pairs = 0;
  /// Median feature flow per frame pair, window mean [px].
  double motion_px = 0.0;
  /// Window mean of the per-pair median reprojection residual of the
  /// features under the gyro's rotation [px]: with the configured IMU
  /// rotation, and with the best of the 24 signed axis permutations, each at
  /// its best clock offset.
  double residual_configured_px = 0.0;
  double residual_best_mounting_px = 0.0;
  /// Another signed axis permutation explains the image motion much better
  /// than the configured imu/R_cam_imu: the rotation contradicts the video.
  bool rotation_contradicts = false;
  /// The best signed axis permutation, as an imu/R_cam_imu to configure.
  Eigen::Quaterniond best_R_cam_imu = Eigen::Quaterniond::Identity();
  /// Estimated correction to add to imu/time_offset [s] (for the suggested
  /// mounting when the configured rotation contradicts the video), and
  /// whether it exceeds offset_warn_s (only judged when the rotation
  /// agrees).
  double offset_correction_s = 0.0;
  bool offset_off = false;
};

/// A live check of the gyro against the video: tracks background features
/// (KLT, forward-backward checked, outside the face) between consecutive
/// frames and measures how well the gyro's rotation, as configured,
/// predicts their motion; compared with the 24 signed axis permutations of
/// the IMU mounting and with clock offsets around the configured one.
/// Catches an IMU rotation or clock offset that disagrees with the image
/// motion within a few seconds of hand shake.
///
/// The features' rays rotate by the camera's relative rotation between the
/// two frames' row times (5 row bands; a pure rotation, fine for a
/// background far compared with the camera's travel). Not thread-safe.
class GyroVideoCheck {
 public:
  /// `R_cam_imu` is the rotation the timeline was built with.
  static Status Create(const CameraIntrinsics& intrinsics,
                       const RowTiming& timing,
                       const Eigen::Quaterniond& R_cam_imu,
                       const GyroVideoCheckOptions& options,
                       std::unique_ptr<GyroVideoCheck>* out);

  /// One frame (8-bit, 1-4 channels, the intrinsics' size) stamped `stamp`;
  /// `face_box` (may be empty) is excluded from tracking. The timeline must
  /// cover the frame's rows plus the offset range (else the pair is skipped).
  void Process(const cv::Mat& image, Time stamp,
               const OrientationTimeline& timeline, const cv::Rect2d& face_box);
  /// A frame whose rotation is not the gyro's (taken from the video): the
  /// pair that would end at it is not formed; the window is kept.
  void SkipFrame() { has_prev_ = false; }
  void Reset();
  const GyroVideoCheckResult& result() const { return result_; }

  /// The 24 proper rotations that permute and flip the axes.
  static const std::vector<Eigen::Quaterniond>& SignedAxisPermutations();

 private:
  GyroVideoCheck(const CameraIntrinsics& intrinsics, const RowTiming& timing,
                 const Eigen::Quaterniond& R_cam_imu,
                 const GyroVideoCheckOptions& options);
  // Tracks between frames a and b, waiting until the gyro covers b's rows
  // plus the offset range.
  struct Pending {
    Time a, b;
    std::vector<Eigen::Vector2d> xa, xb;  // undistorted pixels
    std::vector<double> ya, yb;           // raw rows (row times)
  };
  struct PairRecord {
    Time stamp;
    double motion_px = 0.0;
    std::vector<double> offset_residual;  // configured mounting, per offset
    std::vector<double> grid;  // [permutation * offsets + offset]
  };
  void EvaluateReady(const OrientationTimeline& timeline);
  void Evaluate(const Pending& p, const OrientationTimeline& timeline);
  void Judge();

  const CameraIntrinsics k_;
  const RowTiming timing_;
  const Eigen::Quaterniond R_cam_imu_;
  const GyroVideoCheckOptions options_;
  double scale_ = 1.0;  // tracking image / full image
  std::vector<double> offsets_;
  // The 24 signed permutations as changes of the configured mounting.
  std::vector<Eigen::Matrix3d> mountings_;
  cv::Mat prev_grey_;
  Time prev_stamp_;
  bool has_prev_ = false;
  uint64_t frame_index_ = 0;
  std::deque<Pending> pending_;    // bounded (8)
  std::deque<PairRecord> window_;  // bounded by window_s
  GyroVideoCheckResult result_;
};

}  // namespace steadiface

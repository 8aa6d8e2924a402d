#pragma once

#include <memory>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/camera/rolling_shutter.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/common/time.h"
#include "steadiface_core/visual/scene_trail.h"

namespace steadiface {
namespace visual {
struct BearingPair;
}  // namespace visual

struct VisualRotationOptions {
  /// Features are tracked on a grey copy at most this long [px].
  int max_side_px = 640;
  /// Features tracked at most [count]; refilled when fewer than half remain.
  int max_features = 200;
  /// Smallest distance between two features, in the copy [px].
  double min_distance_px = 15.0;
  /// KLT window side [px, odd] and pyramid levels above the copy [count].
  int klt_window_px = 21;
  int klt_levels = 3;
  /// A feature is tracked only where the picture has this much texture:
  /// the smaller eigenvalue of the window's gradient matrix per pixel
  /// (OpenCV's minEigThreshold; its default is 1e-4) [-]. Sensor noise on a
  /// plain wall stays below it.
  double min_texture = 1e-3;
  /// A feature fits the rotation when it lands within this of its track,
  /// in full-resolution pixels [px].
  double inlier_threshold_px = 2.0;
  /// RANSAC hypotheses (three features each) per frame, at most [count].
  int ransac_iterations = 64;
  /// A tracked feature's position error [px], and how fast a hand's angular
  /// velocity changes [rad/s^2] and how fast that changes [rad/s^3]: weak
  /// priors that keep the motion within the pair from fitting the noise.
  /// Over the two frames' 50 ms a shake's angular velocity bends, so both
  /// are fitted. The priors are about twice what a brisk handheld walk
  /// shows at its 95th percentile: the recorded phone walk (test/data/gyro)
  /// has 10 rad/s^2 and 700 rad/s^3 RMS (22 and 1600 at the 95th
  /// percentile), the simulator's walk (0.7 deg RMS shake up to 12 Hz)
  /// about 28 and 1600 RMS. (At 1000 rad/s^3, below both, the prior bound
  /// the fit: the turn's error on the simulated walks was twice what it is
  /// at 3000.)
  double feature_noise_px = 1.0;
  double alpha_prior_rad_s2 = 60.0;
  double beta_prior_rad_s3 = 3000.0;
  /// A rotation is trusted with at least this many inliers [count] ...
  int min_inliers = 20;
  /// ... or with fewer, down to this many [count], when its fit gives one
  /// frame's turn to within max_turn_error_px: a standard error from the
  /// inliers' spread and residual, in its worst direction [px]. Holding
  /// still costs the frame's whole turn (5-20 px on a walk). Tracks on a
  /// plain wall's sensor noise fit to 0.9-1.7 px; a pale wall's few real
  /// features to 0.1-0.6 px.
  int min_inliers_precise = 8;
  double max_turn_error_px = 0.75;
  /// ... making up at least this fraction of the tracked features [-],
  /// each feature weighted by how long it has moved with the scene (1 when
  /// fresh, up to 5 after four frames).
  double min_inlier_ratio = 0.5;
  /// The subject is left out: the face box grown by this fraction of its
  /// width on each side and above [-], and below it a column this many
  /// face widths wide down to the image's bottom (the body) [-].
  double face_margin = 0.5;
  double body_width = 3.0;
  /// A feature is dropped once it strays from the scene: once any of its
  /// sightings over the last `trail_frames` frames, carried to the present
  /// by the rotations fitted since, lands further than `trail_threshold_px`
  /// from where it is [count, at most 16; 0: never; full-resolution px]. A
  /// near object (a face walking up beside the subject) moves with the
  /// rotation to within the inlier threshold in each frame, but not over
  /// several.
  int trail_frames = 8;
  double trail_threshold_px = 2.0;
  /// Where features strayed from the scene, no fresh feature is taken for
  /// `stray_hold_s` [s] (0: off) within `stray_radius_px` of each [px on
  /// the tracking copy], once at least `stray_min_count` of them (itself
  /// included) strayed within that radius over that time [count]. A near
  /// object's features, dropped as they stray, were otherwise found again
  /// on it at once, each pulling the turn for a few frames before it
  /// strayed in turn; a lone stray is one track's noise.
  double stray_hold_s = 1.0;
  double stray_radius_px = 40.0;
  int stray_min_count = 3;
};

Status ValidateVisualRotationOptions(const VisualRotationOptions& options);

/// One frame's estimate: the camera's angular velocity between the
/// previous frame and this one.
struct VisualRotation {
  /// Trusted: enough inliers, a large enough share of the tracks.
  bool valid = false;
  /// Camera-frame angular velocity at `stamp` [rad/s] (0 when invalid: the
  /// camera is held still rather than moved by a wrong motion).
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();
  /// Its time: half-way between the two frames' middle rows.
  Time stamp;
  /// The angular velocity's rate of change across the pair [rad/s^2]:
  /// omega(t) = omega + alpha (t - stamp) from the previous frame's first
  /// row to this one's last (0 when invalid).
  Eigen::Vector3d alpha = Eigen::Vector3d::Zero();
  /// Its second derivative [rad/s^3]: omega(t) = omega + alpha u +
  /// beta u^2 / 2, u = t - stamp (0 when invalid).
  Eigen::Vector3d beta = Eigen::Vector3d::Zero();
  /// The camera's turn from u0 to u1 seconds after `stamp` (the integral
  /// of omega(t), as a rotation vector in the camera) [rad].
  Eigen::Vector3d Turn(double u0, double u1) const {
    return omega * (u1 - u0) + alpha * (u1 * u1 - u0 * u0) / 2.0 +
           beta * (u1 * u1 * u1 - u0 * u0 * u0) / 6.0;
  }
  /// The angular velocity u seconds after `stamp` [rad/s].
  Eigen::Vector3d RateAt(double u) const { return omega + alpha * u + beta * u * u / 2.0; }
  int tracked = 0;  ///< feature pairs outside the subject [count]
  int inliers = 0;  ///< pairs that fit the rotation [count]
  /// The inliers' share of the pairs, each weighted by its age [-].
  double support = 0.0;
  /// RMS reprojection error of the inliers [px].
  double residual_px = 0.0;
  /// The fit's standard error of the turn across the pair [px].
  double turn_error_px = 0.0;
  double ms = 0.0;  ///< wall time of Process [ms]
};

/// The camera's rotation from the video alone, for a camera without an IMU
/// (or while it drops out): background features tracked from the previous
/// frame (KLT), the subject left out, and a rotation-only motion fitted
/// robustly (RANSAC on triples of features, then Gauss-Newton on the
/// inliers), so that people and objects moving through the view are
/// outliers. The angular velocity varies linearly in time across the pair
/// (a hand's shake changes it within a frame), and each feature moves by
/// its integral between the times of the rows it was seen on (rolling
/// shutter), so each row later gets its own rotation as with a gyro.
/// Causal: frame n's estimate uses frames n-1 and n only. Not thread-safe.
class VisualRotationEstimator {
 public:
  static Status Create(const CameraModel& model, const RowTiming& timing,
                       const VisualRotationOptions& options,
                       std::unique_ptr<VisualRotationEstimator>* out);

  /// One frame: `gray` is 8-bit single-channel at the model's size; `face`
  /// (empty if none) the subject's face box in this frame [px]. The first
  /// frame, and one after Reset(), gives an invalid estimate.
  Status Process(const cv::Mat& gray, Time stamp, const cv::Rect2d& face,
                 VisualRotation* out);
  void Reset();
  /// Keeps `gray` (at `stamp`) as the previous frame without estimating
  /// anything: the cheap step for frames whose rotation the gyro gives
  /// (rotation_source auto), so that the first frame without IMU data has
  /// a pair. Features are found on it only when they are needed.
  Status Remember(const cv::Mat& gray, Time stamp);

 private:
  VisualRotationEstimator(const CameraModel& model, const RowTiming& timing,
                          const VisualRotationOptions& options);
  // Features to track from the copy `small` (outside `mask`), topped up to
  // max_features.
  void Refill(const cv::Mat& small, const cv::Mat& mask);
  // The previous frame's features tracked into `small`, the rotation
  // fitted, the features that fit kept.
  void Track(const cv::Mat& small, const cv::Mat& mask, Time stamp,
             VisualRotation* out);
  // The features tracked, one entry per feature in each vector (the points
  // stay contiguous for KLT).
  struct Tracks {
    std::vector<cv::Point2f> points;  // in the copy
    std::vector<int> age;  // the frames each has moved with the scene for
    std::vector<visual::SceneTrail> trail;  // its sightings carried to the present
    size_t size() const { return points.size(); }
    bool empty() const { return points.empty(); }
    void Clear();
    void Add(const cv::Point2f& p, int a, const visual::SceneTrail& t);
  };
  // The rotation fitted to the tracked pairs (into *out); when trusted,
  // the tracks `kept` narrowed to its inliers that stay on their trails, a
  // frame older, and where the others strayed into *strays.
  void Fit(const std::vector<visual::BearingPair>& pairs, const std::vector<double>& weights,
           Time stamp, VisualRotation* out, Tracks* kept,
           std::vector<cv::Point2f>* strays) const;
  // Keeps where features strayed this frame, for stray_hold_s.
  void RememberStrays(const std::vector<cv::Point2f>& strays, Time stamp);
  // Zeroes `free` around the strays kept that have company.
  void BlockStrays(cv::Mat* free) const;
  cv::Mat SubjectMask(const cv::Size& size, const cv::Rect2d& face) const;
  cv::Mat Copy(const cv::Mat& gray) const;  // the tracking copy of a frame
  Status CheckGray(const cv::Mat& gray) const;  // 8-bit grey, the camera's size

  const CameraModel model_;
  const RowTiming timing_;
  const VisualRotationOptions options_;
  double scale_ = 1.0;  // copy / full resolution
  cv::Mat prev_;        // the previous copy
  std::vector<cv::Mat> prev_pyramid_;  // its KLT pyramid (empty: not built yet)
  Time prev_stamp_;
  Tracks tracks_;  // the previous frame's features
  static constexpr int kMatureAge = 4;  // weight 1 + min(age, 4)
  // Where features strayed recently (in the copy), and when; at most
  // kMaxStrays.
  std::vector<std::pair<cv::Point2f, Time>> strays_;
  static constexpr size_t kMaxStrays = 512;
};

}  // namespace steadiface

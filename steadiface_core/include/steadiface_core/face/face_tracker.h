#pragma once

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/camera/rolling_shutter.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/common/time.h"
#include "steadiface_core/face/face_detector.h"
#include "steadiface_core/face/face_types.h"
#include "steadiface_core/face/head_region_motion.h"
#include "steadiface_core/face/head_turn.h"
#include "steadiface_core/face/landmark_predictor.h"
#include "steadiface_core/face/search_schedule.h"
#include "steadiface_core/gyro/orientation_timeline.h"

namespace steadiface {

struct FaceTrackerOptions {
  FaceDetectorOptions detector;
  /// dlib 68-point shape predictor model file.
  std::string landmark_model_path = kDefaultShapePredictorPath;
  /// While tracking, re-detect every this many frames (near the face only)
  /// to re-anchor the box [frames]. After any failure, detection runs on
  /// the next frame regardless.
  int redetect_every_frames = 15;
  /// The re-detection region is the predicted box enlarged by this [-].
  double redetect_region_scale = 2.2;
  /// Re-detection near the face runs on a copy scaled, down or up, so the
  /// face is about this wide (dlib's HOG finds faces from ~75 px) [px].
  int redetect_face_px = 100;
  /// Faces narrower than this are fitted on a crop upsampled so they are
  /// this wide (face/upsampled_fit.h: a fifth closer to the full-size fit
  /// at 24-40 px); 0: always at the image's size [px].
  int small_face_fit_px = 60;
  /// Keep the lock on a lost face this long before re-acquiring the
  /// largest face anywhere [s].
  double lost_timeout_s = 1.0;
  /// With no face locked (searching), the full-frame detection runs at most
  /// once per this interval [s]; frames in between report not_searched,
  /// except the one half an interval later, which searches one upsampled
  /// tile for faces down to detector.min_face_px (face/search_schedule.h).
  /// A full-frame search costs 14 ms (a tile about as much), most of a
  /// 30 fps frame, so searching every frame would stall a camera with
  /// nobody in view. The first search after a loss or reset is immediate.
  /// 0: every frame, the whole frame and a tile in turn.
  double search_interval_s = 0.1;
  /// Shape plausibility: max RMS residual after similarity alignment to the
  /// locked face's shape, relative to the face scale [-].
  double max_shape_residual = 0.2;
  /// Landmark extent over box size must lie in [min, max] [-].
  double min_spread_ratio = 0.55;
  double max_spread_ratio = 1.6;
  /// Max jump of the landmark centre from its gyro-compensated prediction,
  /// relative to the face scale [-].
  double max_jump = 1.2;
  /// Min normalized cross-correlation of the aligned face patch with the
  /// locked face's [-].
  double min_appearance = 0.45;
  /// Min normalized cross-correlation of each region of the aligned patch
  /// (eyes, nose, mouth) with the locked face's: below it the face is
  /// partly occluded and not used [-].
  double min_region_appearance = 0.5;
  /// Side of the aligned face patch for the appearance check [px].
  int appearance_patch_px = 40;
  /// How fast the reference patch follows the face while tracking [0-1].
  double appearance_update_rate = 0.05;
  /// The locked face's references (shape and patch) are taken again from an
  /// accepted frame whose |yaw| is this much below theirs: a face locked
  /// while turned is then still recognised as it turns back to the camera
  /// (a turned face's far eye and cheek differ most from a frontal one's;
  /// an occluded frame is never accepted, so never becomes a reference).
  /// 0 = the references are kept from the lock [rad].
  double relock_yaw_step_rad = 0.05;
  /// A locked face whose landmarks are given up after it was last seen
  /// turned by at least follow_min_yaw_rad is still a head in view, turned
  /// past what the landmark model fits: its last landmarks are carried by
  /// the head region's image motion (HeadRegionMotion) for at most this
  /// long after the last fit, and the stabilizer keeps holding the head;
  /// 0 = off [s].
  double follow_turned_s = 3.0;
  /// ... from this |yaw| of the fitted landmarks: the largest over the
  /// last fits, forgotten at 0.3 rad/s (a face lost while facing the camera
  /// is covered or gone, and is held, not followed) [rad].
  double follow_min_yaw_rad = 0.3;
  /// A locked face whose landmarks fail while it faces the camera (a hand
  /// over part of it, or blur) is followed by the translation of the head
  /// region's visible parts (HeadRegionMotion's median track, beyond the
  /// camera's rotation) for at most this long after the last fit; the
  /// parts the cover hides fail their tracks, and a median that does not
  /// continue the head's own motion (follow_max_speed_change) is the
  /// cover's, so the face is then held. 0 = off: held from the first
  /// failed frame [s].
  double follow_covered_s = 0.5;
  /// ... only when the last fit's whole-face appearance (the aligned
  /// patch's correlation with the locked face's) was at least this. A
  /// cover starts in one region of a face that still looks like itself; a
  /// head whipping round fades the whole face over its last fits and is
  /// lost near min_appearance, before PnP's yaw reaches follow_min_yaw_rad.
  /// Followed by its translation, that turn's swing was held as the
  /// head's motion; it is held instead. 0 = every face lost while facing
  /// the camera is followed [-].
  double follow_covered_min_appearance = 0.6;
  /// ... and every followed frame, covered or turned, must move on with
  /// the head's own motion of the frame before within this many face
  /// scales (RMS landmark radius) per frame, and at least 2 px; else the
  /// face is held [-].
  double follow_max_speed_change = 0.15;
  /// ... or within this many times the RMS change of the head's own motion
  /// from one fitted frame to the next, over the last fitted frames (about
  /// 10, exponentially weighted), when that is larger: a head that jitters
  /// more than the face scale's share is followed as it moves [-].
  double follow_speed_change_noise = 3.0;
  /// How the head region's motion is measured.
  HeadRegionMotionOptions region_motion;
  /// The followed head turns about an axis this far behind its landmarks,
  /// in face scales (RMS landmark radius) (face/head_turn.h). The pipeline
  /// sets it to the stabilizer's dynamic.pose_pivot_depth, so the followed
  /// head and the pose-invariant centre share one model; 0: the head is
  /// followed by its translation only [-].
  double head_pivot_depth = 1.5;
  /// Estimate yaw/pitch/roll with solvePnP.
  bool estimate_head_pose = true;
};

Status ValidateFaceTrackerOptions(const FaceTrackerOptions& options);

/// Face information extraction (paper §3.1): detect, lock the face of
/// interest (largest at first sight, kept until lost for lost_timeout_s),
/// and fit 68 landmarks every frame by tracking: the box is predicted from
/// the previous landmarks moved by the gyro's rotation between the frames,
/// and detection re-runs only every N frames or after a failure. Every
/// frame's landmarks must pass explicit checks (shape, spread, jump,
/// appearance) to count. Not thread-safe; one instance per stream.
class FaceTracker {
 public:
  /// Loads the landmark model and builds the detector; errors name the
  /// missing file and the package that ships it.
  static Status Create(const CameraModel& model,
                       const FaceTrackerOptions& options,
                       std::unique_ptr<FaceTracker>* out);

  /// One frame. `image` is 8-bit with 1, 3 (BGR) or 4 (BGRA) channels at the
  /// camera model's size. `timeline` and `timing` (both optional) enable the
  /// gyro-compensated prediction. Bad input returns an error and a FaceInfo
  /// with failure kBadInput; tracking state is kept.
  Status Process(const cv::Mat& image, Time stamp,
                 const OrientationTimeline* timeline, const RowTiming* timing,
                 FaceInfo* info);

  /// Landmarks produced elsewhere (68 points, raw pixels). Runs the same
  /// checks except appearance (no image), and the same face-of-interest
  /// state machine; an empty vector means "no face this frame".
  Status ProcessExternal(const std::vector<Eigen::Vector2d>& landmarks_px,
                         double external_confidence, Time stamp,
                         const OrientationTimeline* timeline,
                         const RowTiming* timing, FaceInfo* info);

  /// Drops the lock (time jumped, new epoch).
  void Reset();

  TrackingState state() const { return state_; }
  const FaceTrackerOptions& options() const { return options_; }

 private:
  FaceTracker(const CameraModel& model, const FaceTrackerOptions& options);

  // Process's two paths: a full-frame search while no face is locked, and
  // tracking the locked (or recently lost) face where the gyro puts it.
  void Search(const cv::Mat& gray, const SearchStep& step, Time stamp, FaceInfo* info);
  void Track(const cv::Mat& gray, const cv::Rect& full, Time stamp,
             const OrientationTimeline* timeline, const RowTiming* timing, bool rot_ok,
             FaceInfo* info);

  // Shared by both paths once landmarks exist for this frame.
  struct Candidate {
    std::vector<Eigen::Vector2d> landmarks;
    cv::Rect2d box;
    bool detected = false;
  };
  bool Evaluate(const cv::Mat* gray, const Candidate& c, bool acquiring,
                const Eigen::Vector2d* predicted_centre, FaceInfo* info,
                cv::Mat* patch) const;
  // Evaluate's appearance check.
  FaceFailure CheckAppearance(const cv::Mat& gray, const Candidate& c, bool acquiring,
                              FaceInfo* info, cv::Mat* patch, double* score_sum,
                              int* n_scores) const;
  void Accept(const Candidate& c, bool acquiring, const cv::Mat& patch,
              Time stamp, FaceInfo* info);
  // Accept, the head's own motion since the frame before when
  // `predicted_centre` (where the camera's rotation alone moved the face)
  // is given and the face was located then, and the region Follow tracks
  // from.
  void TakeFit(const cv::Mat& gray, const Candidate& c, bool acquiring, const cv::Mat& patch,
               const Eigen::Vector2d* predicted_centre, Time stamp, FaceInfo* info);
  // Takes the references again from an accepted face turned nearer the
  // camera than they were (options_.relock_yaw_step_rad).
  void Relock(const Candidate& c, bool acquiring, const cv::Mat& patch, const FaceInfo& info);
  // A face whose landmarks failed, turned (options_.follow_turned_s) or
  // covered (options_.follow_covered_s): its last landmarks moved with the
  // head region; false when not followed.
  bool Follow(const cv::Mat& gray, Time stamp, const Eigen::Vector2d& predicted_centre,
              const OrientationTimeline* timeline, const RowTiming* timing, FaceInfo* info);
  // Follow's choice: false when neither kind of follow applies; the head
  // model is set up on the first followed frame.
  bool StartFollow(Time stamp, double scale);
  // Ends a follow (and the head's own motion it carried); returns false.
  bool StopFollowing();
  // The last fits' poses: remembered after each fit (`consecutive`: the
  // fit before was of the frame before), and the median of the last three,
  // the pose a covered face holds.
  void RememberPose(bool posed, bool consecutive, const FaceInfo& info);
  void HeldPose(double* yaw, double* pitch) const;
  // PnP's head pose of `landmarks` (lens distortion removed) [rad].
  bool Pose(const std::vector<Eigen::Vector2d>& landmarks, double* yaw, double* pitch,
            double* roll) const;
  // Whether a fit may end the turned follow: its yaw near the followed
  // head's (kRefitMaxYawChange), or enough fits turned away already.
  bool RefitAgreesWithTurn(const Candidate& c);
  // Where the camera's rotation moves a still point from the previous
  // frame's pixel into this frame's (face_prediction.cc); zero without the
  // gyro.
  Eigen::Vector2d CameraShift(const Eigen::Vector2d& from_px, Time stamp,
                              const OrientationTimeline* timeline, const RowTiming* timing) const;
  // Where a still point seen at `px` under real rotation R0 is seen under
  // R1 (PredictLandmarks, CameraShift); false when it does not project.
  bool SeenAfterRotation(const Eigen::Vector2d& px, const Eigen::Quaterniond& R0,
                         const Eigen::Quaterniond& R1, Eigen::Vector2d* out) const;
  void Fill(const std::vector<Eigen::Vector2d>& landmarks, FaceInfo* info) const;
  bool PredictLandmarks(Time stamp, const OrientationTimeline* timeline,
                        const RowTiming* timing,
                        std::vector<Eigen::Vector2d>* predicted) const;
  cv::Rect2d BoxFromLandmarks(const std::vector<Eigen::Vector2d>& lm) const;
  // CheckAppearance's per-region correlation (eyes, nose, mouth), `A` the
  // patch's affine map from the image of `image` size.
  double RegionAppearance(const cv::Mat& patch, const cv::Mat& A, const cv::Size& image) const;
  // The face patch aligned on the eyes and mouth; `A` (optional) gets the
  // image -> patch affine map (2x3, CV_64F).
  bool AlignedPatch(const cv::Mat& gray, const std::vector<Eigen::Vector2d>& lm,
                    cv::Mat* patch, cv::Mat* A = nullptr) const;
  // The 68 landmarks in `box` (upsampled when the face is small).
  bool Fit(const cv::Mat& gray, const cv::Rect2d& box,
           std::vector<Eigen::Vector2d>* landmarks) const;
  bool DetectAndFit(const cv::Mat& gray, const cv::Rect& roi,
                    const cv::Rect2d* near, Candidate* c, double* detect_ms);
  void MarkFailure(FaceFailure f, Time stamp, FaceInfo* info);
  Eigen::Quaterniond MidRotation(Time stamp, const OrientationTimeline* tl,
                                 const RowTiming* timing, bool* ok) const;

  const CameraModel model_;
  const FaceTrackerOptions options_;
  std::unique_ptr<FaceDetector> detector_;
  std::unique_ptr<LandmarkPredictor> predictor_;
  std::unique_ptr<SearchSchedule> schedule_;  // where the next search looks
  std::vector<Eigen::Vector3d> head_model_;

  TrackingState state_ = TrackingState::kSearching;
  std::vector<Eigen::Vector2d> last_landmarks_;
  std::vector<Eigen::Vector2d> reference_shape_;  // similarity-normalized
  cv::Mat reference_patch_;                      // CV_32F
  double reference_yaw_ = 0.0;                   // |yaw| of the references [rad]
  HeadRegionMotion region_motion_;               // the head's crop, for Follow
  bool following_ = false;                       // Follow's state:
  bool following_covered_ = false;               // ... by translation only
  bool past_profile_ = false;  // a follow ended past the profile: none until the next fit
  HeadTurn head_turn_;                           // the followed head
  int refit_rejects_ = 0;  // fits RefitAgreesWithTurn turned away in this follow
  // The head's own motion over the last frame, beyond the camera's
  // rotation, when it was located in both frames [px/frame].
  Eigen::Vector2d own_shift_ = Eigen::Vector2d::Zero();
  bool have_own_shift_ = false;
  // The mean square of that motion's change between fitted frames
  // [px^2/frame^2], and whether it has a value.
  double own_change_ms_ = 0.0;
  bool have_own_change_ = false;
  std::vector<Eigen::Vector2d> fitted_landmarks_;  // the last fit's
  bool have_fitted_pose_ = false;                // the last fit's pose:
  double fitted_yaw_ = 0.0, fitted_pitch_ = 0.0, fitted_roll_ = 0.0;  // [rad]
  double fitted_yaw_rate_ = 0.0;                 // over consecutive fits [rad/frame]
  // The yaw and pitch of the last consecutive fits (newest last), for a
  // covered face's held pose: their median [rad].
  double recent_yaws_[3] = {}, recent_pitches_[3] = {};
  int recent_poses_ = 0;
  bool fitted_last_frame_ = false;
  double recent_abs_yaw_ = 0.0;                  // the turn lately, for Follow [rad]
  double fitted_appearance_ = 1.0;               // the last fit's whole-face appearance [-]
  Time last_located_;                            // last fitted or followed
  Time last_frame_;                              // the previous frame's stamp
  bool have_last_frame_ = false;
  // Box relative to the landmark extent: (dx, dy, sx, sy).
  Eigen::Vector4d box_model_ = Eigen::Vector4d(0.0, -0.1, 1.05, 1.05);
  Time last_seen_;
  bool have_last_rotation_ = false;
  Eigen::Quaterniond last_rotation_ = Eigen::Quaterniond::Identity();
  int frames_since_detect_ = 0;
  int frames_tracked_ = 0;
  bool force_detect_ = true;
};

}  // namespace steadiface

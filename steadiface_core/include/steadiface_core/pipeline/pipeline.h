#pragma once

#include <cmath>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/camera/rolling_shutter.h"
#include "steadiface_core/check/gyro_video_check.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/composite/compositor.h"
#include "steadiface_core/face/face_tracker.h"
#include "steadiface_core/gyro/orientation_timeline.h"
#include "steadiface_core/stabilizer/stabilizer.h"
#include "steadiface_core/view/dynamic_crop.h"
#include "steadiface_core/view/gravity.h"
#include "steadiface_core/view/shake_path.h"
#include "steadiface_core/visual/visual_rotation.h"
#include "steadiface_core/warp/warper.h"

namespace steadiface {

/// Where landmarks come from.
enum class LandmarkSource {
  kDlib,      ///< the built-in detector + dlib 68-point tracker
  kExternal,  ///< landmarks supplied with each frame (another node)
  kNone,      ///< no face processing: gyro-only stabilization
};

/// Where the real camera's rotation comes from.
enum class RotationSource {
  kImu,     ///< the gyro samples given to AddGyro
  kVisual,  ///< the video itself (visual/visual_rotation.h); AddGyro ignored
  /// The gyro, and the video for the frames the owner marks as without IMU
  /// data (SetImuMissing), continuing the same orientation timeline both
  /// ways. With the IMU covering every frame the output is kImu's exactly.
  kAuto,
};

/// All options of one stream.
struct PipelineOptions {
  CameraModelOptions camera;
  RollingShutterOptions shutter;
  /// The gyro timeline. Unlike a bare timeline, a stream may extrapolate the
  /// gyro up to 50 ms past its newest sample: a live node's late frames
  /// (late_frame_policy "extrapolate") need it.
  OrientationTimelineOptions imu = [] {
    OrientationTimelineOptions o;
    o.max_extrapolation_s = 0.05;
    return o;
  }();
  /// kVisual: a camera without an IMU (the gyro check is off then); kAuto:
  /// the IMU while it flows, the video while it does not.
  RotationSource rotation_source = RotationSource::kAuto;
  VisualRotationOptions visual;
  LandmarkSource landmark_source = LandmarkSource::kDlib;
  FaceTrackerOptions face;
  StabilizerOptions stabilizer;
  WarpOptions warp;
  /// The output's crop: warp.output.crop_ratio on every frame (kFixed), or
  /// a dynamic crop between crop.widest_crop_ratio and it.
  DynamicCropOptions crop;
  /// The level horizon from the accelerometer (off by default).
  HorizonOptions horizon;
  /// The composite (warp mode composite): matte, plate, blend.
  CompositeOptions composite;
  /// Produce the stabilized image (false: poses only, e.g. for scoring).
  bool render_output = true;
  /// The live check of the gyro's configuration against the video.
  GyroVideoCheckOptions gyro_video_check;
};

Status ValidatePipelineOptions(const PipelineOptions& options);

/// Options that are valid and run, but are known to work poorly together:
/// a sentence that names the conflict and what to set instead, or empty.
/// Not an error: the node WARNs with it on /diagnostics ("view") and the
/// tools print it. Today one: the composite (warp.mode kComposite) with the
/// dynamic crop, whose zoom its matte and plate do not follow
/// (docs/evaluation.md, "The dynamic crop").
std::string OptionsConflict(const PipelineOptions& options);

/// The stabilizer options a warp needs: in layered mode the background
/// layer is solved every frame, and H is held within subject_reach of where
/// it shows the face; a subject_reach of 0 becomes what the band absorbs,
/// warp.layered.blend.band_width x max_offset jaw widths.
StabilizerOptions ForWarp(const StabilizerOptions& options, const WarpOptions& warp);

struct PipelineTimings {
  double face_ms = 0.0;
  double check_ms = 0.0;  ///< GyroVideoCheck
  double stabilizer_ms = 0.0;
  double mesh_ms = 0.0;
  double maps_ms = 0.0;
  double remap_ms = 0.0;
  /// Composite mode: the matte, the plate and the blend.
  double composite_ms = 0.0;
  /// The dynamic crop: the need of the solved pose(s) and the crop's update.
  double crop_ms = 0.0;
  double total_ms = 0.0;
};

/// The layered warp's view of one frame (warp mode layered).
struct LayeredFrame {
  bool active = false;  ///< warp mode is layered
  /// The subject region (output px) and its blend weight.
  SubjectRegion region;
  /// What the mesh optimization did (offsets, distortion, timing).
  LayerBlendReport blend;
};

/// The composite's view of one frame (warp mode composite).
struct CompositeFrame {
  bool active = false;  ///< warp mode is composite
  /// The subject region in the background layer's view (output px).
  SubjectRegion region;
  /// What the compositor did (zero when the output was not rendered).
  CompositeReport report;
};

/// One processed frame.
struct PipelineFrame {
  FaceInfo face;
  StabilizerFrame stabilizer;
  /// Stabilized, cropped, scaled output (empty when render_output is off or
  /// the warp refused the pose).
  cv::Mat output;
  /// Intrinsics of `output` (virtual focal and principal offset; with the
  /// dynamic crop, the frame's zoom).
  CameraIntrinsics output_intrinsics;
  /// The crop the frame was made with, and the dynamic crop's need and
  /// target.
  CropReport crop;
  /// The level horizon (output/horizon).
  struct Horizon {
    HorizonMode mode = HorizonMode::kOff;
    /// E_h was in the solve: gravity known, the rotation from the gyro.
    bool active = false;
    /// Why not, when the mode asks for it: "no accelerometer" (gravity not
    /// known yet: no or only rejected readings) or "visual rotation"; empty
    /// otherwise.
    std::string inactive_reason;
    /// The roll against gravity of the output's scene (the background
    /// layer's pose where there is one) and of the real camera (middle row)
    /// [rad], HorizonRoll; NaN while gravity is not known.
    double output_roll_rad = NAN;
    double real_roll_rad = NAN;
  };
  Horizon horizon;
  PipelineTimings timings;
  /// The gyro-vs-video check over its window (GyroVideoCheck).
  GyroVideoCheckResult gyro_video_check;
  /// The rotation of this frame came from the video (kVisual, or kAuto
  /// without IMU data), and what the video gave.
  bool rotation_from_video = false;
  VisualRotation visual;
  /// The first frame of the rotation from the video (at the start, or after
  /// Reset()): no turn is known across its rows until the next frame, so it
  /// is not to be shown (output empty). Its middle row's rotation is known:
  /// the stabilizer and the warp take it as their first frame. Shown
  /// uncorrected, it made the next frame jump by its rolling shutter's skew.
  bool withheld = false;
  /// The clock offset correction the timeline applied to this frame, on top
  /// of imu/time_offset (gyro_video_check/apply_offset; else 0) [s].
  double imu_offset_applied_s = 0.0;
  /// The layered warp (warp mode layered).
  LayeredFrame layered;
  /// The composite (warp mode composite).
  CompositeFrame composite;
  /// ProcessFrameDeferred: the frame's warp mesh and output size, for
  /// RenderDeferred (empty otherwise).
  WarpMesh mesh;
  cv::Size output_size;
};

/// The whole per-frame chain for one camera + IMU stream: gyro timeline,
/// face information, stabilizer and warp (product steps 1-5). The ROS
/// nodelet, the offline bag tool and the evaluation tools all drive this
/// one class; the ROS layer only converts messages.
///
/// Causal and deterministic. Not thread-safe: the owner serializes calls.
class Pipeline {
 public:
  static Status Create(const CameraIntrinsics& intrinsics,
                       const PipelineOptions& options,
                       std::unique_ptr<Pipeline>* out);

  /// Buffers one gyro sample (rejections are counted in timeline stats).
  SampleResult AddGyro(const GyroSample& sample);
  /// Takes one accelerometer reading (after the gyro sample of the same
  /// message): gravity for the level horizon. Returns true when it was
  /// accepted (HorizonOptions: near 1 g, covered by the gyro).
  bool AddAccel(const AccelSample& sample);
  /// The gravity estimate's counters (accepted, rejected readings).
  const GravityEstimator& gravity() const { return gravity_; }
  /// rotation_source kAuto: whether the next frames lack IMU data (the
  /// gyro does not cover them), so that their rotation comes from the
  /// video. Ignored in the other modes.
  void SetImuMissing(bool missing) { imu_missing_ = missing; }

  /// Evaluation only (steadiface_evaluate --true-head): the next frame's
  /// face has its pose-invariant head centre at `pixel` [raw image px], not
  /// where the tracker puts it (Stabilizer::SetTrueHeadCentre; the
  /// tracker's landmarks move with it, its yaw and every check stay).
  void SetTrueHeadCentre(const Eigen::Vector2d& pixel);

  /// True when the gyro covers the frame's last row (plus nothing else is
  /// needed to process it).
  bool GyroCovers(Time stamp) const;
  /// Capture time of the frame's last row (camera clock).
  Time LastRowTime(Time stamp) const { return timing_.LastRowTime(stamp); }

  /// Processes one frame. `external_landmarks` (raw pixels, 68 points, may
  /// be empty = no face) is used with LandmarkSource::kExternal.
  Status ProcessFrame(const cv::Mat& image, Time stamp,
                      const std::vector<Eigen::Vector2d>* external_landmarks,
                      double external_confidence, PipelineFrame* out);

  /// ProcessFrame without the rendering: `out->mesh` and `out->output_size`
  /// describe the warp, `out->output` stays empty. (Warp mode composite
  /// renders at once: its plate is the stream's state; the mesh stays
  /// empty and RenderDeferred keeps the output.) RenderDeferred renders it
  /// later, on any thread, while this pipeline goes on with the next frame
  /// (a two-stage pipeline; the rendering is SampleMesh, bit-for-bit
  /// ProcessFrame's with direct sampling or fixed-point maps).
  Status ProcessFrameDeferred(const cv::Mat& image, Time stamp,
                              const std::vector<Eigen::Vector2d>* external_landmarks,
                              double external_confidence, PipelineFrame* out);
  /// Renders a deferred frame's output from its own mesh (touches no
  /// pipeline state: thread-safe). Sets timings.remap_ms and adds it to
  /// timings.total_ms (the frame's work, processing and render).
  static void RenderDeferred(const cv::Mat& image, PipelineFrame* frame);

  /// Without gyro: the plain centre crop (identity pose), same output size
  /// and intrinsics as stabilized frames; the trajectory is not touched.
  Status Passthrough(const cv::Mat& image, PipelineFrame* out);

  /// Replaces the stabilizer's tunable options from the next frame on.
  Status UpdateStabilizerOptions(const StabilizerOptions& options);

  /// Replaces the warp mode and the layered warp's options from the next
  /// frame on (rebuilds the warper; switching to layered starts the
  /// background layer's trajectory). Validated; on error nothing changes.
  Status UpdateLayering(WarpMode mode, const LayeredWarpOptions& layered);

  /// Time jumped back: forget gyro, face lock, trajectory and the applied
  /// clock offset correction (a fresh start).
  void Reset();

  const OrientationTimeline& timeline() const { return timeline_; }
  const Stabilizer& stabilizer() const { return *stabilizer_; }
  const Warper& warper() const { return *warper_; }
  /// The compositor (warp mode composite; else null).
  const Compositor* compositor() const { return compositor_.get(); }
  /// Composite mode: keep the plate's use per frame (Compositor::KeepPlateUse;
  /// for scoring and debugging).
  void KeepCompositePlateUse(bool keep) {
    keep_plate_use_ = keep;
    if (compositor_ != nullptr) compositor_->KeepPlateUse(keep);
  }
  const CameraModel& camera_model() const { return model_; }
  const RowTiming& row_timing() const { return timing_; }
  const PipelineOptions& options() const { return options_; }

 private:
  // ProcessFrame's pieces: the face (tracker or external landmarks; the
  // grey image the tracker and the check share into *grey; returns the
  // usable observation, stored in *observation, or null), and the warp (a
  // pose warp, or the layered mesh; rendered unless deferred).
  const FaceObservation* FaceStep(const cv::Mat& image, Time stamp,
                                  const std::vector<Eigen::Vector2d>* external,
                                  double external_confidence, cv::Mat* grey,
                                  FaceObservation* observation, PipelineFrame* f);
  // The gyro-vs-video check on this frame (skipped when the video rotated it).
  void CheckStep(const cv::Mat& grey, Time stamp, PipelineFrame* f);
  Status WarpStep(const cv::Mat& image, Time stamp, const FaceObservation* obs,
                  PipelineFrame* f);
  // WarpStep in composite mode: both layers' pictures and their composite.
  Status CompositeStep(const cv::Mat& image, Time stamp, const FaceObservation* obs,
                       PipelineFrame* f);
  // rotation_source kVisual: the rotation from this frame and the previous
  // one, fed into the timeline as a camera-frame angular velocity.
  Status VisualStep(const cv::Mat& grey, Time stamp, PipelineFrame* f);
  Pipeline(const CameraModel& model, const PipelineOptions& options);
  void ApplyOffsetEstimate(Time stamp);
  // The level horizon for this frame's solve, and its report.
  void HorizonStep(PipelineFrame* f);
  void HorizonReportStep(PipelineFrame* f) const;
  // The dynamic crop: the margin this frame's solved pose(s) asked for
  // moves the next frame's crop (kFixed: the report only).
  void CropStep(Time stamp, PipelineFrame* f);

  const CameraModel model_;
  PipelineOptions options_;
  const RowTiming timing_;
  OrientationTimeline timeline_;
  std::unique_ptr<FaceTracker> tracker_;
  std::unique_ptr<Stabilizer> stabilizer_;
  std::unique_ptr<Warper> warper_;
  std::unique_ptr<GyroVideoCheck> check_;  // null when disabled
  std::unique_ptr<VisualRotationEstimator> visual_;  // rotation_source kVisual
  cv::Rect2d last_face_box_;                         // kVisual: left out of the features
  Time visual_mid_;                                  // the last frame's middle row
  bool has_visual_mid_ = false;
  bool imu_missing_ = false;  // kAuto: SetImuMissing
  // kAuto: the timeline's newest nodes came from the video, and the gyro
  // samples that arrived since, held back until the video has reached them
  // (a hand-back never bridges the gap by integrating across it).
  bool video_newest_ = false;
  std::deque<GyroSample> pending_gyro_;
  static constexpr size_t kMaxPendingGyro = 4096;  // 20 s at 200 Hz
  // Hands the held-back gyro samples to the timeline once the video's
  // newest node is within a sample's spacing of them; drops those it passed.
  void HandBackToGyro();
  std::unique_ptr<SubjectRegionTracker> region_;  // layered and composite mode
  std::unique_ptr<Compositor> compositor_;       // composite mode
  std::unique_ptr<DynamicCrop> crop_;
  ShakePath shake_path_;  // the dynamic crop's room for the shake
  GravityEstimator gravity_;  // the level horizon's gravity
  bool has_crop_stamp_ = false;
  Time crop_stamp_;
  cv::Mat subject_picture_;                      // composite: the subject layer's
  bool keep_plate_use_ = false;
  bool has_last_stamp_ = false;
  Time last_stamp_;
  // gyro_video_check/apply_offset: the previous frame's stamp (rate limit).
  bool has_check_stamp_ = false;
  Time check_stamp_;
  // ProcessFrameDeferred in progress: mesh only, copied into the frame.
  bool defer_render_ = false;
};

}  // namespace steadiface

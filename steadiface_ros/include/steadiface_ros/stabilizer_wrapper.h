#pragma once

#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <geometry_msgs/PointStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/time.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <visualization_msgs/MarkerArray.h>

#include "steadiface/FaceLandmarks.h"
#include "steadiface/StabilizerState.h"
#include "steadiface_core/pipeline/frame_scheduler.h"
#include "steadiface_core/pipeline/pipeline.h"
#include "steadiface_ros/frusta_markers.h"
#include "steadiface_ros/params.h"
#include "steadiface_ros/render_worker.h"

namespace steadiface_ros {

/// Where the wrapper's results go: ROS publishers (nodelet, node) or an
/// output bag (steadiface_bag). Same calls in the same order either way.
class OutputSink {
 public:
  virtual ~OutputSink() = default;
  virtual void PublishImage(const sensor_msgs::ImagePtr& image,
                            const sensor_msgs::CameraInfoPtr& info) = 0;
  /// Whether the stabilized image's pixels are consumed. When false the
  /// frame is still rendered, but its pixels are not copied into a message:
  /// the wrapper calls PublishOutputInfo instead of PublishImage (the bag
  /// tool with only a report to write). Asked once per frame.
  virtual bool WantsImage() const { return true; }
  /// The stabilized camera_info of a frame whose image is not wanted.
  virtual void PublishOutputInfo(const sensor_msgs::CameraInfoPtr& /*info*/) {}
  virtual void PublishLandmarks(const steadiface::FaceLandmarks& msg) = 0;
  virtual void PublishState(const steadiface::StabilizerState& msg) = 0;
  virtual void PublishTf(const std::vector<geometry_msgs::TransformStamped>& tf) = 0;
  /// The target head centre H as a 3D point 1 m along its ray, in the
  /// stabilized camera's frame (for rviz).
  virtual void PublishHeadTarget(const geometry_msgs::PointStamped& /*p*/) {}
  /// The real and virtual cameras as rviz frusta with trails (FrustaMarkers),
  /// built only when this returns true (a viewer is subscribed).
  virtual bool WantsMarkers() const { return false; }
  virtual void PublishMarkers(const visualization_msgs::MarkerArray& /*m*/) {}
  /// Debug images are rendered only when this returns true.
  virtual bool WantsDebugImage() const = 0;
  virtual void PublishDebugImage(const sensor_msgs::ImagePtr& image) = 0;
  /// Throttled log lines (the nodelet maps them to NODELET_*_THROTTLE).
  virtual void Warn(const std::string& key, const std::string& text) = 0;
  virtual void Error(const std::string& key, const std::string& text) = 0;
  /// Time jumped backwards and the wrapper reset; a front end drops state
  /// keyed by time (the nodelet clears its TF buffer, which would otherwise
  /// refuse the new epoch's transforms as TF_OLD_DATA).
  virtual void OnTimeJump() {}
  /// A frame the pipeline has just stabilized, before it is rendered or
  /// published: the pipeline's warper still holds its warp (the bag tool
  /// scores it against ground truth).
  virtual void OnFrameProcessed(const steadiface::PipelineFrame& /*frame*/,
                                const steadiface::Pipeline& /*pipeline*/) {}
  /// The clock the latency in `state` is measured on (the ROS clock in the
  /// nodelet); zero (the default, offline) leaves latency_ms at 0.
  virtual ros::Time Now() const { return ros::Time(); }
};

/// Counters behind the diagnostics, all since start.
struct WrapperCounters {
  uint64_t images_in = 0, imu_in = 0, frames_out = 0;
  uint64_t dropped_bad_image = 0;       ///< encoding, size, step, size vs camera_info
  uint64_t dropped_bad_info = 0;        ///< uncalibrated / invalid camera_info
  uint64_t dropped_no_gyro = 0;         ///< gyro never covered within the wait (policy drop)
  uint64_t dropped_queue_full = 0;      ///< burst beyond frame_queue_size
  uint64_t dropped_old_stamp = 0;       ///< not after the previous frame
  uint64_t dropped_pipeline_error = 0;  ///< stabilizer/warp refused the frame
  uint64_t extrapolated = 0;            ///< processed with extrapolated gyro
  uint64_t passthrough = 0;             ///< published unstabilized (no IMU)
  uint64_t from_video = 0;              ///< rotation from the video (visual, or auto without IMU)
  uint64_t withheld = 0;                ///< the video's first frame (no turn across its rows yet)
  uint64_t accel_in = 0;                ///< IMU messages with an accelerometer reading
  uint64_t imu_rejected = 0;            ///< non-finite, implausible, duplicate, out of order
  uint64_t imu_gaps = 0;                ///< gaps longer than imu_gap_warn
  uint64_t time_jumps = 0;              ///< time went backwards: full reset
  uint64_t rebuilds = 0;                ///< camera geometry changed: maps rebuilt
  uint64_t landmarks_bad = 0;           ///< ~landmarks_in messages rejected
  uint64_t tf_skipped = 0;              ///< TF not newer than the last one
};

/// Where imu/R_cam_imu comes from (imu_extrinsics_from_tf).
enum class ExtrinsicsState {
  kConfigured,     ///< the parameter (imu_extrinsics_from_tf off, or no TF lookup)
  kWaitingForImu,  ///< the IMU's frame is not known yet (no IMU message)
  kSameFrame,      ///< IMU and camera share a frame: identity, no TF needed
  kWaitingForTf,   ///< TF has no transform between them yet: the parameter meanwhile
  kFromTf,         ///< taken from TF
};

/// A snapshot for the diagnostics tasks.
struct WrapperStatus {
  WrapperCounters counters;
  bool pipeline_ready = false;
  bool imu_ever = false;
  double seconds_since_imu = 1e9;        ///< data time since the newest IMU sample
  double gyro_latency_s = 0.0;           ///< newest gyro minus last row of the last frame
  steadiface::TimelineStats timeline;
  steadiface::StabilizerStats stabilizer;
  steadiface::TrackingState face_state = steadiface::TrackingState::kSearching;
  std::string face_failure;
  double face_confidence = 0.0;
  std::string last_solver_termination;
  double last_solver_ms = 0.0;
  int last_solver_iterations = 0;
  std::string last_error;
  /// Why the landmark model could not be loaded; non-empty means the wrapper
  /// runs gyro-only although landmark_source is dlib.
  std::string landmark_model_error;
  /// The gyro-vs-video check as of the last frame.
  steadiface::GyroVideoCheckResult gyro_video_check;
  /// rotation_source: "imu", "visual" or "auto"; whether the last frame's
  /// rotation came from the video, and what the video gave.
  std::string rotation_source = "imu";
  bool last_from_video = false;
  steadiface::VisualRotation visual;
  /// The clock offset correction applied on top of imu/time_offset [s].
  double imu_offset_applied_s = 0.0;
  /// The level horizon: output/horizon, the last frame's report, and the
  /// accelerometer readings the gravity estimate took and left out (far
  /// from 1 g, not yet covered by the gyro) since the pipeline was built.
  std::string horizon_mode = "off";
  steadiface::PipelineFrame::Horizon horizon;
  uint64_t accel_accepted = 0, accel_rejected = 0;
  /// The last frame's crop (output/crop).
  steadiface::CropReport crop;
  /// Why the configured view and warp mode do not go together (the
  /// "view" diagnostic WARNs with it); empty when they do.
  std::string view_conflict;
  /// The IMU extrinsics' source, and the frames of their TF lookup.
  ExtrinsicsState extrinsics = ExtrinsicsState::kConfigured;
  std::string extrinsics_from, extrinsics_to;
};

/// The one object behind the nodelet, the node and the offline bag tool: it
/// converts messages, hands IMU samples and frames to the core's
/// FrameScheduler (which holds the stream's rules: gyro coverage, the
/// late-frame policy, time jumps, bounded queues), runs the core Pipeline
/// on the frames it releases and hands the results to an OutputSink.
///
/// Threading: OnImu / OnImage / OnLandmarks / OnTimer / Flush must be
/// serialized by the owner (the nodelet runs them on one callback queue).
/// RequestStabilizerOptions() may be called from any thread (the
/// dynamic_reconfigure server's): it only stores the request under its own
/// mutex; the next frame applies it. With `pipelined`, a processed frame
/// renders on the wrapper's one RenderWorker thread while the owner's
/// thread processes the next; the owner's thread publishes it (the sink is
/// only ever called from the owner's thread).
class StabilizerWrapper {
 public:
  /// `extrinsic_lookup(imu_frame, camera_frame, &R_cam_imu)` (optional) is
  /// asked for the IMU -> camera rotation when the frames differ.
  using ExtrinsicLookup =
      std::function<bool(const std::string&, const std::string&, Eigen::Quaterniond*)>;

  StabilizerWrapper(const steadiface::PipelineOptions& pipeline,
                    const WrapperOptions& options, OutputSink* sink,
                    ExtrinsicLookup extrinsic_lookup = {});
  /// Waits for a frame still rendering (pipelined); publishes nothing more.
  ~StabilizerWrapper();

  void OnImu(const sensor_msgs::Imu& msg);
  void OnImage(const sensor_msgs::ImageConstPtr& image,
               const sensor_msgs::CameraInfoConstPtr& info, const ros::Time& now);
  void OnLandmarks(const steadiface::FaceLandmarks& msg);
  /// Processes queued frames whose wait ran out; `now` is ROS time live,
  /// the current message time offline.
  void OnTimer(const ros::Time& now);
  /// End of input (bag): processes everything still queued.
  void Flush();

  void RequestStabilizerOptions(const steadiface::StabilizerOptions& options);
  /// The same for the warp mode and the layered warp's options (applied
  /// only when they differ from those in effect: rebuilding the warper
  /// restarts the layered warp's smoothing).
  void RequestLayering(steadiface::WarpMode mode, const steadiface::LayeredWarpOptions& layered);

  /// Counters, the stabilizer's and the IMU's health, as of now (for the
  /// diagnostics, the bag report and tests).
  WrapperStatus CurrentStatus() const;
  const steadiface::PipelineOptions& pipeline_options() const { return options_; }

 private:
  struct Pending {
    sensor_msgs::ImageConstPtr image;
    sensor_msgs::CameraInfoConstPtr info;
    ros::Time received;
  };
  void Drain(const ros::Time& now, bool flush);
  void Process(const Pending& p, bool late);
  bool EnsurePipeline(const sensor_msgs::CameraInfo& info);
  void ResetAll(const char* why);
  void ApplyPendingOptions();
  // `started`: the sink's clock when processing began (latency parts).
  void Publish(const Pending& p, const steadiface::PipelineFrame& frame,
               const cv::Mat& input, bool extrapolated, bool passthrough,
               const ros::Time& started);
  // Process's pieces: the message as an image of the camera's size (else
  // counted, reported and false), and a frame without IMU data
  // (passthrough_without_imu).
  bool ToCheckedImage(const Pending& p, cv::Mat* image);
  void PublishPassthrough(const Pending& p, const cv::Mat& image, const ros::Time& started);
  // Publish's pieces: the stabilized image and camera_info; landmarks and
  // state (with latencies); TF (strictly increasing stamps); rviz frusta and
  // the head target; the debug image; the status the diagnostics report.
  void PublishOutputImage(const steadiface::PipelineFrame& frame,
                          const std_msgs::Header& out_header);
  void PublishLandmarksAndState(const Pending& p, const steadiface::PipelineFrame& frame,
                                const std_msgs::Header& lm_header, bool extrapolated,
                                const ros::Time& started, const ros::Time& published);
  // Takes imu/R_cam_imu from TF once it resolves (then rebuilds the
  // pipeline); tried again on every frame until then.
  void ResolveExtrinsics(const std::string& camera_frame);
  // The integrated gyro's frame: world_frame, or <camera_frame>_world.
  std::string WorldFrame(const std::string& camera_frame) const;
  void PublishTransforms(const steadiface::PipelineFrame& frame,
                         const std_msgs::Header& in_header, const std::string& camera_frame,
                         const std_msgs::Header& out_header);
  void PublishRvizExtras(const steadiface::PipelineFrame& frame,
                         const std_msgs::Header& in_header, const std_msgs::Header& out_header);
  void PublishDebugImage(const steadiface::PipelineFrame& frame, const cv::Mat& input,
                         const std_msgs::Header& in_header);
  void UpdateStatus(const steadiface::PipelineFrame& frame, const std_msgs::Header& in_header);
  // pipelined: waits for the held frame's rendering and publishes it.
  void FinishHeld();

  steadiface::PipelineOptions options_;
  const WrapperOptions wrapper_options_;
  OutputSink* sink_;
  ExtrinsicLookup extrinsic_lookup_;

  std::unique_ptr<steadiface::Pipeline> pipeline_;
  // Keeps the landmark model loaded from start-up (shared with pipelines).
  std::unique_ptr<steadiface::LandmarkPredictor> preloaded_model_;
  sensor_msgs::CameraInfo pipeline_info_;
  std::string imu_frame_;
  bool extrinsic_resolved_ = false;
  // Frames waiting for the gyro and the recent gyro for rebuilds (bounded).
  steadiface::FrameScheduler<Pending> scheduler_;
  FrustaMarkers frusta_;  // bounded trails
  std::vector<Eigen::Vector2d> external_landmarks_;
  double external_confidence_ = 0.0;
  ros::Time last_external_stamp_;
  ros::Time last_tf_stamp_;
  WrapperCounters counters_;
  WrapperStatus status_;

  // pipelined: the processed frame whose output renders on `render_`.
  struct Held {
    Pending p;
    steadiface::PipelineFrame frame;
    cv::Mat image;
    bool extrapolated = false;
    ros::Time started;
  };
  std::unique_ptr<Held> held_;
  RenderWorker render_;  // declared after held_: destroyed (joined) first

  std::mutex options_mutex_;
  bool options_pending_ = false;
  steadiface::StabilizerOptions requested_options_;
  bool layering_pending_ = false;
  steadiface::WarpMode requested_mode_ = steadiface::WarpMode::kGlobal;
  steadiface::LayeredWarpOptions requested_layered_;
};

}  // namespace steadiface_ros

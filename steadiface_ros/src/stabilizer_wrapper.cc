#include "steadiface_ros/stabilizer_wrapper.h"

#include <optional>

#include "steadiface_ros/msg_conversion.h"
#include "steadiface_ros/time_conversion.h"

namespace steadiface_ros {
namespace {

// The receive clock as the scheduler takes it: zero means none (the IMU
// callback, end of input), so no wait runs out.
std::optional<steadiface::Time> ReceiveTime(const ros::Time& now) {
  if (now.isZero()) return std::nullopt;
  return ToCoreTime(now);
}

bool SameGeometry(const sensor_msgs::CameraInfo& a, const sensor_msgs::CameraInfo& b) {
  return a.width == b.width && a.height == b.height && a.K == b.K && a.D == b.D &&
         a.distortion_model == b.distortion_model && a.binning_x == b.binning_x &&
         a.binning_y == b.binning_y && a.roi.x_offset == b.roi.x_offset &&
         a.roi.y_offset == b.roi.y_offset && a.roi.width == b.roi.width &&
         a.roi.height == b.roi.height;
}

}  // namespace

StabilizerWrapper::StabilizerWrapper(const steadiface::PipelineOptions& pipeline,
                                     const WrapperOptions& options, OutputSink* sink,
                                     ExtrinsicLookup extrinsic_lookup)
    : options_(pipeline),
      wrapper_options_(options),
      sink_(sink),
      extrinsic_lookup_(std::move(extrinsic_lookup)),
      scheduler_(options.scheduler) {
  // Load the ~100 MB landmark model now, not on the first frame (which
  // would stall the image queue for a second).
  if (options_.landmark_source != steadiface::LandmarkSource::kNone) {
    const steadiface::Status s =
        steadiface::LandmarkPredictor::Load(options_.face.landmark_model_path, &preloaded_model_);
    if (!s.ok() && options_.landmark_source == steadiface::LandmarkSource::kDlib) {
      // The model is a one-time install (not a rosdep key): without it,
      // stabilize from the gyro alone and keep saying why.
      status_.landmark_model_error = s.message();
      options_.landmark_source = steadiface::LandmarkSource::kNone;
      sink_->Error("landmark_model", s.message() + ": stabilizing from the gyro alone");
    } else if (!s.ok()) {
      sink_->Error("landmark_model", s.message());
    }
  }
}

// render_ (declared after held_) waits for the frame in hand as it goes.
StabilizerWrapper::~StabilizerWrapper() = default;

void StabilizerWrapper::FinishHeld() {
  render_.Wait();
  if (!held_) return;
  std::unique_ptr<Held> h = std::move(held_);
  Publish(h->p, h->frame, h->image, h->extrapolated, false, h->started);
}

void StabilizerWrapper::RequestStabilizerOptions(const steadiface::StabilizerOptions& o) {
  std::lock_guard<std::mutex> lock(options_mutex_);
  requested_options_ = o;
  options_pending_ = true;
}

void StabilizerWrapper::RequestLayering(steadiface::WarpMode mode,
                                        const steadiface::LayeredWarpOptions& layered) {
  std::lock_guard<std::mutex> lock(options_mutex_);
  requested_mode_ = mode;
  requested_layered_ = layered;
  layering_pending_ = true;
}

void StabilizerWrapper::ApplyPendingOptions() {
  steadiface::StabilizerOptions o;
  bool layering = false, stabilizer = false;
  steadiface::WarpMode mode;
  steadiface::LayeredWarpOptions layered;
  {
    std::lock_guard<std::mutex> lock(options_mutex_);
    stabilizer = options_pending_;
    layering = layering_pending_;
    o = requested_options_;
    mode = requested_mode_;
    layered = requested_layered_;
    options_pending_ = layering_pending_ = false;
  }
  if (layering && !steadiface::SameLayering(mode, layered, options_.warp)) {
    if (pipeline_) {
      const steadiface::Status s = pipeline_->UpdateLayering(mode, layered);
      if (!s.ok()) {
        sink_->Error("reconfigure", "reconfigure rejected: " + s.message());
        return;
      }
    }
    options_.warp.mode = mode;
    options_.warp.layered = layered;
  }
  if (!stabilizer) return;
  if (pipeline_) {
    const steadiface::Status s = pipeline_->UpdateStabilizerOptions(o);
    if (!s.ok()) {
      sink_->Error("reconfigure", "reconfigure rejected: " + s.message());
      return;
    }
  }
  // As requested: the pipeline derives what layered mode adds to them.
  options_.stabilizer = o;
}

void StabilizerWrapper::ResetAll(const char* why) {
  ++counters_.time_jumps;
  sink_->Warn("time_jump", std::string("time jumped backwards (") + why +
                               "): resetting gyro timeline, face tracker and stabilizer");
  FinishHeld();  // the last frame of the old epoch
  if (pipeline_) pipeline_->Reset();
  scheduler_.Reset();
  last_tf_stamp_ = ros::Time();
  frusta_.Clear();
  sink_->OnTimeJump();
}

void StabilizerWrapper::OnImu(const sensor_msgs::Imu& msg) {
  ++counters_.imu_in;
  if (imu_frame_.empty()) imu_frame_ = msg.header.frame_id;
  const steadiface::Time stamp = ToCoreTime(msg.header.stamp);
  if (scheduler_.IsGyroTimeJump(stamp)) ResetAll("IMU stamp");
  const double gap_s = scheduler_.GyroGap(stamp);
  if (gap_s > 0.0) {
    ++counters_.imu_gaps;
    sink_->Warn("imu_gap", "IMU gap of " + std::to_string(gap_s) + " s");
  }
  const steadiface::GyroSample g = ToGyroSample(msg);
  steadiface::SampleResult r = steadiface::SampleResult::kAccepted;
  if (pipeline_) {
    r = pipeline_->AddGyro(g);
  } else if (!g.angular_velocity.allFinite()) {
    r = steadiface::SampleResult::kNonFinite;
  }
  if (r != steadiface::SampleResult::kAccepted) {
    ++counters_.imu_rejected;
    sink_->Warn(std::string("imu_") + steadiface::SampleResultName(r),
                std::string("IMU sample rejected: ") + steadiface::SampleResultName(r));
    return;
  }
  // Gravity for the level horizon, from the same message (the pipeline
  // counts what it leaves out).
  steadiface::AccelSample a;
  if (ToAccelSample(msg, &a)) {
    ++counters_.accel_in;
    if (pipeline_) pipeline_->AddAccel(a);
  }
  // The scheduler keeps a bounded copy for rebuilding the pipeline.
  scheduler_.OnGyroAccepted(g, steadiface::FromSeconds(options_.imu.buffer_duration_s),
                            static_cast<size_t>(options_.imu.max_samples));
  // Frames the gyro now covers; waits run out in OnTimer / OnImage.
  Drain(ros::Time(), false);
}

void StabilizerWrapper::OnLandmarks(const steadiface::FaceLandmarks& msg) {
  std::vector<Eigen::Vector2d> pts;
  double conf = 0.0;
  const steadiface::Status s = FromMsg(msg, &pts, &conf);
  if (!s.ok()) {
    ++counters_.landmarks_bad;
    sink_->Warn("landmarks_in", s.message());
    pts.clear();
  }
  external_landmarks_ = pts;
  external_confidence_ = conf;
  last_external_stamp_ = msg.header.stamp;
}

bool StabilizerWrapper::EnsurePipeline(const sensor_msgs::CameraInfo& info) {
  if (pipeline_ && SameGeometry(info, pipeline_info_)) return true;
  FinishHeld();  // published with the pipeline that processed it
  steadiface::CameraIntrinsics k;
  steadiface::Status s = ToCameraIntrinsics(info, &k);
  if (!s.ok()) {
    ++counters_.dropped_bad_info;
    sink_->Error("camera_info", s.message());
    status_.last_error = s.message();
    return false;
  }
  const steadiface::PipelineOptions& o = options_;
  std::unique_ptr<steadiface::Pipeline> p;
  s = steadiface::Pipeline::Create(k, o, &p);
  if (!s.ok()) {
    sink_->Error("pipeline", "cannot build the stabilizer: " + s.message());
    status_.last_error = s.message();
    return false;
  }
  if (pipeline_) ++counters_.rebuilds;
  for (const auto& g : scheduler_.recent_gyro()) p->AddGyro(g);
  pipeline_ = std::move(p);
  pipeline_info_ = info;
  scheduler_.ForgetLastFrame();
  return true;
}

void StabilizerWrapper::ResolveExtrinsics(const std::string& camera_frame) {
  // Looked up on every frame until TF has it (a static TF may come late,
  // the IMU's frame is known from its first message); then the pipeline is
  // rebuilt with it, the recent gyro replayed in the new rotation.
  if (!wrapper_options_.imu_extrinsics_from_tf || !extrinsic_lookup_ || extrinsic_resolved_) {
    return;
  }
  if (imu_frame_.empty()) {
    status_.extrinsics = ExtrinsicsState::kWaitingForImu;
    return;
  }
  if (imu_frame_ == camera_frame) {
    status_.extrinsics = ExtrinsicsState::kSameFrame;
    return;
  }
  status_.extrinsics_from = imu_frame_;
  status_.extrinsics_to = camera_frame;
  Eigen::Quaterniond q;
  if (!extrinsic_lookup_(imu_frame_, camera_frame, &q)) {
    status_.extrinsics = ExtrinsicsState::kWaitingForTf;
    sink_->Warn("extrinsics", "no TF from IMU frame '" + imu_frame_ + "' to camera frame '" +
                                  camera_frame + "' yet; using imu/R_cam_imu until it comes");
    return;
  }
  options_.imu.R_cam_imu = q;
  extrinsic_resolved_ = true;
  status_.extrinsics = ExtrinsicsState::kFromTf;
  if (pipeline_) {
    FinishHeld();
    pipeline_.reset();
    ++counters_.rebuilds;
  }
}

void StabilizerWrapper::OnImage(const sensor_msgs::ImageConstPtr& image,
                                const sensor_msgs::CameraInfoConstPtr& info,
                                const ros::Time& now) {
  ++counters_.images_in;
  if (!image || !info) {
    ++counters_.dropped_bad_info;
    sink_->Error("camera_info", "image without camera_info");
    return;
  }
  const steadiface::Time stamp = ToCoreTime(image->header.stamp);
  if (scheduler_.IsFrameTimeJump(stamp)) ResetAll("image stamp");
  using Admission = steadiface::FrameScheduler<Pending>::Admission;
  const Admission a = scheduler_.Admit({image, info, now}, stamp, ToCoreTime(now));
  if (a == Admission::kOldStamp) {
    ++counters_.dropped_old_stamp;
    sink_->Warn("old_stamp", "image stamp not after the previous frame's: dropped");
    return;
  }
  if (a == Admission::kQueuedDroppedOldest) {
    ++counters_.dropped_queue_full;
    sink_->Warn("queue_full", "frame queue full (gyro too slow?): dropping the oldest frame");
  }
  Drain(now, false);
}

void StabilizerWrapper::OnTimer(const ros::Time& now) { Drain(now, false); }

void StabilizerWrapper::Flush() {
  Drain(ros::Time(), true);
  FinishHeld();
}

void StabilizerWrapper::Drain(const ros::Time& now, bool flush) {
  const std::optional<steadiface::Time> at = ReceiveTime(now);
  while (const auto* q = scheduler_.Front()) {
    const Pending& p = q->frame;
    const std::string frame_id = wrapper_options_.camera_frame.empty()
                                     ? p.image->header.frame_id
                                     : wrapper_options_.camera_frame;
    ResolveExtrinsics(frame_id);
    if (!EnsurePipeline(*p.info)) {
      scheduler_.DropFront();
      continue;
    }
    auto released = scheduler_.ReleaseFront(pipeline_->GyroCovers(q->stamp), at, flush);
    if (!released) break;  // keep waiting (FIFO: later frames too)
    Process(released->queued.frame, released->late);
  }
  // pipelined: a processed frame waits for the next one at most
  // pipeline_hold (and not at all at the end of input).
  if (held_ && scheduler_.HoldRanOut(ToCoreTime(held_->p.received), at, flush)) FinishHeld();
}

void StabilizerWrapper::Process(const Pending& p, bool late) {
  const ros::Time started = sink_->Now();
  // Options (and warper rebuilds) apply between frames: the held frame
  // renders from its own mesh copy, so it is not affected.
  ApplyPendingOptions();
  cv::Mat image;
  if (!ToCheckedImage(p, &image)) return;
  const steadiface::Time stamp = ToCoreTime(p.image->header.stamp);
  // The visual rotation source needs no IMU: every frame is processed. In
  // auto, a frame the gyro does not cover takes its rotation from the video
  // instead of passing through, being extrapolated or dropped.
  using steadiface::FrameDisposition;
  using steadiface::RotationSource;
  FrameDisposition d = options_.rotation_source == RotationSource::kVisual
                           ? FrameDisposition::kProcess
                           : scheduler_.Dispose(stamp, late);
  if (options_.rotation_source == RotationSource::kAuto) {
    pipeline_->SetImuMissing(d != FrameDisposition::kProcess);
    d = FrameDisposition::kProcess;
  }
  if (d == steadiface::FrameDisposition::kNoImu) {
    PublishPassthrough(p, image, started);
    return;
  }
  if (d == steadiface::FrameDisposition::kDropLate) {
    ++counters_.dropped_no_gyro;
    sink_->Warn("late_frame", "gyro did not cover the frame within max_gyro_wait: dropped");
    return;
  }
  steadiface::PipelineFrame frame;
  const bool extrapolated = d == steadiface::FrameDisposition::kExtrapolate;
  const bool use_external =
      options_.landmark_source == steadiface::LandmarkSource::kExternal;
  // External landmarks count only for the image they were made for.
  std::vector<Eigen::Vector2d> none;
  const std::vector<Eigen::Vector2d>* ext =
      use_external && last_external_stamp_ == p.image->header.stamp ? &external_landmarks_ : &none;
  const bool pipelined = wrapper_options_.pipelined;
  // Pipelined, this runs while the previous frame renders on render_.
  const steadiface::Status s =
      pipelined ? pipeline_->ProcessFrameDeferred(image, stamp, ext, external_confidence_, &frame)
                : pipeline_->ProcessFrame(image, stamp, ext, external_confidence_, &frame);
  if (!s.ok()) {
    ++(late ? counters_.dropped_no_gyro : counters_.dropped_pipeline_error);
    sink_->Warn(late ? "late_frame" : "pipeline",
                std::string(late ? "gyro could not be extrapolated far enough: " : "frame refused: ") +
                    s.message());
    status_.last_error = s.message();
    return;
  }
  if (extrapolated) ++counters_.extrapolated;
  scheduler_.OnFrameDone(stamp);
  if (frame.withheld) {
    // The rotation from the video starts: this frame's rows get their turn
    // from the next frame, so it is not published (PipelineFrame::withheld).
    ++counters_.withheld;
    return;
  }
  sink_->OnFrameProcessed(frame, *pipeline_);
  if (!pipelined) {
    Publish(p, frame, image, extrapolated, false, started);
    return;
  }
  // Publish the previous frame (its rendering overlapped this frame's
  // processing), then render this one on the worker.
  FinishHeld();
  held_.reset(new Held{p, std::move(frame), image, extrapolated, started});
  Held* h = held_.get();
  render_.Start([h] { steadiface::Pipeline::RenderDeferred(h->image, &h->frame); });
}

bool StabilizerWrapper::ToCheckedImage(const Pending& p, cv::Mat* image) {
  // The image as OpenCV sees it, of the camera's size; else counted,
  // reported and false.
  steadiface::Status s = ToCvImage(*p.image, image);
  if (!s.ok()) {
    ++counters_.dropped_bad_image;
    sink_->Error("image", s.message());
    status_.last_error = s.message();
    return false;
  }
  const steadiface::CameraIntrinsics& k = pipeline_->camera_model().intrinsics();
  if (image->cols != k.width || image->rows != k.height) {
    ++counters_.dropped_bad_image;
    const std::string m = "image is " + std::to_string(image->cols) + "x" +
                          std::to_string(image->rows) + " but camera_info says " +
                          std::to_string(k.width) + "x" + std::to_string(k.height);
    sink_->Error("image_size", m);
    status_.last_error = m;
    return false;
  }
  return true;
}

void StabilizerWrapper::UpdateStatus(const steadiface::PipelineFrame& frame,
                                     const std_msgs::Header& in_header) {
  status_.gyro_video_check = frame.gyro_video_check;
  status_.last_from_video = frame.rotation_from_video;
  if (frame.rotation_from_video) {
    status_.visual = frame.visual;
    ++counters_.from_video;
  }
  status_.imu_offset_applied_s = frame.imu_offset_applied_s;
  status_.horizon = frame.horizon;
  status_.crop = frame.crop;
  status_.face_state = frame.face.state;
  status_.face_failure = steadiface::FaceFailureName(frame.face.failure);
  status_.face_confidence = frame.face.confidence;
  status_.last_solver_termination = frame.stabilizer.solver.termination;
  status_.last_solver_ms = frame.stabilizer.solver.time_ms;
  status_.last_solver_iterations = frame.stabilizer.solver.iterations;
  if (scheduler_.have_gyro()) {
    const steadiface::Time stamp = ToCoreTime(in_header.stamp);
    status_.gyro_latency_s = (ToRosTime(scheduler_.last_gyro_stamp()) - in_header.stamp).toSec() -
                             steadiface::ToSeconds(pipeline_->LastRowTime(stamp) - stamp);
  }
}

WrapperStatus StabilizerWrapper::CurrentStatus() const {
  WrapperStatus s = status_;
  s.counters = counters_;
  s.pipeline_ready = pipeline_ != nullptr;
  s.imu_ever = scheduler_.have_gyro();
  s.rotation_source = options_.rotation_source == steadiface::RotationSource::kVisual ? "visual"
                      : options_.rotation_source == steadiface::RotationSource::kAuto ? "auto"
                                                                                       : "imu";
  if (pipeline_) {
    s.timeline = pipeline_->timeline().stats();
    s.stabilizer = pipeline_->stabilizer().stats();
    s.accel_accepted = pipeline_->gravity().accepted();
    s.accel_rejected = pipeline_->gravity().rejected();
  }
  s.horizon_mode = steadiface::HorizonModeName(options_.horizon.mode);
  s.view_conflict = steadiface::OptionsConflict(options_);
  return s;
}

}  // namespace steadiface_ros

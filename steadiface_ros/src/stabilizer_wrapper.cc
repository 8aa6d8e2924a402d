#include "steadiface_ros/stabilizer_wrapper.h"

#include <optional>

#include <sensor_msgs/image_encodings.h>

#include "steadiface_core/pipeline/debug_overlay.h"
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

void StabilizerWrapper::PublishPassthrough(const Pending& p, const cv::Mat& image,
                                           const ros::Time& started) {
  // Without IMU data: the unstabilized frame, or nothing.
  if (!wrapper_options_.passthrough_without_imu) {
    ++counters_.dropped_no_gyro;
    sink_->Error("no_imu", "no IMU data: frame dropped (passthrough_without_imu: false)");
    return;
  }
  steadiface::PipelineFrame frame;
  const steadiface::Status s = pipeline_->Passthrough(image, &frame);
  if (!s.ok()) {
    ++counters_.dropped_pipeline_error;
    return;
  }
  ++counters_.passthrough;
  sink_->Error("no_imu", "no IMU data: publishing unstabilized frames");
  scheduler_.OnFrameDone(ToCoreTime(p.image->header.stamp));
  FinishHeld();  // in order
  Publish(p, frame, image, false, true, started);
}

void StabilizerWrapper::Publish(const Pending& p, const steadiface::PipelineFrame& frame,
                                const cv::Mat& input, bool extrapolated, bool passthrough,
                                const ros::Time& started) {
  std_msgs::Header in_header = p.image->header;
  const std::string camera_frame =
      wrapper_options_.camera_frame.empty() ? in_header.frame_id : wrapper_options_.camera_frame;
  std_msgs::Header out_header = in_header;
  out_header.frame_id = camera_frame + wrapper_options_.stabilized_suffix;
  PublishOutputImage(frame, out_header);
  const ros::Time published = sink_->Now();
  if (!passthrough) {
    std_msgs::Header lm_header = in_header;
    lm_header.frame_id = camera_frame;
    PublishLandmarksAndState(p, frame, lm_header, extrapolated, started, published);
    PublishTransforms(frame, in_header, camera_frame, out_header);
    PublishRvizExtras(frame, lm_header, out_header);
    if (sink_->WantsDebugImage()) PublishDebugImage(frame, input, in_header);
    UpdateStatus(frame, in_header);
  }
  ++counters_.frames_out;
}

void StabilizerWrapper::PublishOutputImage(const steadiface::PipelineFrame& frame,
                                           const std_msgs::Header& out_header) {
  if (!frame.output.empty()) {
    sensor_msgs::CameraInfoPtr info(
        new sensor_msgs::CameraInfo(ToCameraInfo(frame.output_intrinsics, out_header)));
    if (sink_->WantsImage()) {
      const std::string enc = frame.output.channels() == 1
                                  ? sensor_msgs::image_encodings::MONO8
                                  : frame.output.channels() == 4
                                        ? sensor_msgs::image_encodings::BGRA8
                                        : sensor_msgs::image_encodings::BGR8;
      sink_->PublishImage(ToImageMsg(out_header, enc, frame.output), info);
    } else {
      sink_->PublishOutputInfo(info);
    }
  }
}

void StabilizerWrapper::PublishLandmarksAndState(const Pending& p,
                                                 const steadiface::PipelineFrame& frame,
                                                 const std_msgs::Header& lm_header,
                                                 bool extrapolated, const ros::Time& started,
                                                 const ros::Time& published) {
  const std_msgs::Header& in_header = p.image->header;
  sink_->PublishLandmarks(ToMsg(frame.face, lm_header));
  steadiface::StabilizerState state = ToMsg(frame, lm_header, extrapolated);
  if (!published.isZero() && published >= in_header.stamp) {
    state.latency_ms = (published - in_header.stamp).toSec() * 1e3;
    if (!p.received.isZero() && p.received >= in_header.stamp) {
      state.arrival_latency_ms = (p.received - in_header.stamp).toSec() * 1e3;
    }
    if (!started.isZero() && !p.received.isZero() && started >= p.received) {
      state.gyro_wait_ms = (started - p.received).toSec() * 1e3;
    }
  }
  sink_->PublishState(state);
}

std::string StabilizerWrapper::WorldFrame(const std::string& camera_frame) const {
  return wrapper_options_.world_frame.empty() ? camera_frame + "_world"
                                              : wrapper_options_.world_frame;
}

void StabilizerWrapper::PublishTransforms(const steadiface::PipelineFrame& frame,
                                          const std_msgs::Header& in_header,
                                          const std::string& camera_frame,
                                          const std_msgs::Header& out_header) {
  // TF, strictly increasing within an epoch.
  if (last_tf_stamp_.isZero() || in_header.stamp > last_tf_stamp_) {
    std::vector<geometry_msgs::TransformStamped> tf;
    geometry_msgs::TransformStamped t;
    t.header.stamp = in_header.stamp;
    t.header.frame_id = camera_frame;
    t.child_frame_id = out_header.frame_id;
    // Child (virtual) coordinates -> parent (real) coordinates: R_r R_v^-1.
    const Eigen::Quaterniond rel =
        (frame.stabilizer.R_r * frame.stabilizer.R_v.conjugate()).normalized();
    t.transform = ToTransformMsg(rel);
    if (rel.coeffs().allFinite()) tf.push_back(t);
    if (frame.stabilizer.background.valid) {
      // The background layer's virtual camera beside the subject's.
      geometry_msgs::TransformStamped bt = t;
      bt.child_frame_id = out_header.frame_id + "_background";
      const Eigen::Quaterniond brel =
          (frame.stabilizer.R_r * frame.stabilizer.background.R_v.conjugate()).normalized();
      bt.transform = ToTransformMsg(brel);
      if (brel.coeffs().allFinite()) tf.push_back(bt);
    }
    if (wrapper_options_.publish_world_tf) {
      // The integrated gyro as a child of the camera frame, which keeps the
      // parent its driver or URDF gives it: world coordinates -> camera
      // coordinates, R_r.
      geometry_msgs::TransformStamped w;
      w.header.stamp = in_header.stamp;
      w.header.frame_id = camera_frame;
      w.child_frame_id = WorldFrame(camera_frame);
      const Eigen::Quaterniond q_cw = frame.stabilizer.R_r.normalized();
      w.transform = ToTransformMsg(q_cw);
      if (q_cw.coeffs().allFinite()) tf.push_back(w);
    }
    sink_->PublishTf(tf);
    last_tf_stamp_ = in_header.stamp;
  } else {
    ++counters_.tf_skipped;
  }
}

void StabilizerWrapper::PublishRvizExtras(const steadiface::PipelineFrame& frame,
                                          const std_msgs::Header& in_header,
                                          const std_msgs::Header& out_header) {
  // rviz frusta: camera -> world orientations are the inverses of R_r, R_v.
  frusta_.Add(frame.stabilizer.R_r.conjugate(), frame.stabilizer.R_v.conjugate());
  if (sink_->WantsMarkers()) {
    std_msgs::Header world_header = in_header;
    world_header.frame_id = WorldFrame(in_header.frame_id);  // (the camera frame)
    const visualization_msgs::MarkerArray m = frusta_.Make(
        world_header, pipeline_->camera_model().intrinsics(), frame.output_intrinsics);
    if (!m.markers.empty()) sink_->PublishMarkers(m);
  }
  if (frame.stabilizer.has_target) {
    // H's ray in the virtual camera: K_v(t)^-1 [H; 1].
    const Eigen::Vector3d ray = (pipeline_->camera_model().VirtualK(frame.stabilizer.t).inverse() *
                                 frame.stabilizer.H.homogeneous())
                                    .normalized();
    if (ray.allFinite()) {
      geometry_msgs::PointStamped p;
      p.header = out_header;
      p.point.x = ray.x();
      p.point.y = ray.y();
      p.point.z = ray.z();
      sink_->PublishHeadTarget(p);
    }
  }
}

void StabilizerWrapper::PublishDebugImage(const steadiface::PipelineFrame& frame,
                                          const cv::Mat& input,
                                          const std_msgs::Header& in_header) {
  cv::Mat dbg;
  steadiface::DrawDebugOverlay(input, pipeline_->camera_model(),
                               pipeline_->stabilizer().protrusion(), &frame.face,
                               &frame.stabilizer, &dbg);
  if (frame.layered.active) {
    const steadiface::OutputGeometry& og = pipeline_->warper().output_geometry();
    steadiface::DrawLayeredOverlay(frame.mesh.source.empty() ? pipeline_->warper().mesh()
                                                             : frame.mesh,
                                   frame.layered.region,
                                   frame.layered.blend, og.width(), og.height(), &dbg);
  }
  if (frame.composite.active && pipeline_->compositor() != nullptr) {
    // The warper's last mesh is the background layer's (rendered second).
    steadiface::DrawCompositeOverlay(pipeline_->warper().mesh(), *pipeline_->compositor(), &dbg);
  }
  sink_->PublishDebugImage(
      ToImageMsg(in_header, sensor_msgs::image_encodings::BGR8, dbg));
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
  return s;
}

}  // namespace steadiface_ros

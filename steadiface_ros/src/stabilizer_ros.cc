#include "steadiface_ros/stabilizer_ros.h"

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>

#include "image_decoder.h"
#include "steadiface_ros/msg_conversion.h"

namespace steadiface_ros {

StabilizerRos::StabilizerRos(ros::NodeHandle nh, ros::NodeHandle pnh, const std::string& name)
    : nh_(nh), pnh_(pnh), name_(name) {
  // 1. Parameters (and the stream wrapper built from them).
  if (!LoadParameters()) return;
  // 2. dynamic_reconfigure, with its own mutex; starts from the loaded options.
  StartReconfigure();
  // 3. Publishers and diagnostics.
  Advertise();
  StartDiagnostics();
  // 4. Subscribers: IMU never lazy, with a large queue.
  bool builtin_compressed = false;
  const std::string transport = Subscribe(&builtin_compressed);
  timer_ = nh_.createTimer(ros::Duration(0.01), &StabilizerRos::OnTimer, this);
  last_imu_wall_ = ros::WallTime::now();
  ok_ = true;
  const std::string intrinsics = info_source_->has_file_info()
                                     ? "camera_info or " + info_source_->url()
                                     : std::string("camera_info");
  ROS_INFO("[%s] ready: image_raw (%s%s) + %s -> image_stabilized, imu, landmark source %s",
           name_.c_str(), transport.c_str(), builtin_compressed ? ", built-in decoder" : "",
           intrinsics.c_str(),
           pipeline_options_.landmark_source == steadiface::LandmarkSource::kDlib
               ? "dlib"
               : pipeline_options_.landmark_source == steadiface::LandmarkSource::kExternal
                     ? "topic"
                     : "none");
}

bool StabilizerRos::LoadParameters() {
  std::unique_ptr<ParamSource> params = RosParams(pnh_);
  const steadiface::Status s = LoadOptions(*params, &pipeline_options_, &wrapper_options_);
  if (!s.ok()) {
    ROS_ERROR("[%s] invalid parameters, the stabilizer will not run: %s", name_.c_str(),
              s.message().c_str());
    return false;
  }
  info_source_.reset(new CameraInfoSource([this](bool is_error, const std::string& text) {
    if (is_error) {
      ROS_ERROR_STREAM_THROTTLE(5.0, "[" << name_ << "] " << text);
    } else {
      ROS_INFO_STREAM("[" << name_ << "] " << text);
    }
  }));
  const steadiface::Status info_status = info_source_->Load(wrapper_options_.camera_info_url);
  if (!info_status.ok()) {
    ROS_ERROR("[%s] invalid camera_info_url, the stabilizer will not run: %s", name_.c_str(),
              info_status.message().c_str());
    return false;
  }
  tf_buffer_.reset(new tf2_ros::Buffer);
  tf_listener_.reset(new tf2_ros::TransformListener(*tf_buffer_, nh_));
  wrapper_.reset(new StabilizerWrapper(
      pipeline_options_, wrapper_options_, this,
      [this](const std::string& a, const std::string& b, Eigen::Quaterniond* q) {
        return LookupExtrinsic(a, b, q);
      }));

  return true;
}

void StabilizerRos::StartReconfigure() {
  reconfigure_.reset(
      new dynamic_reconfigure::Server<steadiface::SteadifaceConfig>(reconfigure_mutex_, pnh_));
  {
    boost::recursive_mutex::scoped_lock lock(reconfigure_mutex_);
    reconfigure_->updateConfig(ConfigFromOptions(pipeline_options_));
  }
  reconfigure_->setCallback(
      [this](steadiface::SteadifaceConfig& c, uint32_t level) { OnReconfigure(c, level); });
}

void StabilizerRos::Advertise() {
  it_.reset(new image_transport::ImageTransport(nh_));
  // Its own camera namespace, so its camera_info does not collide with the
  // input's: image_stabilized/image_raw + image_stabilized/camera_info.
  image_pub_ = it_->advertiseCamera("image_stabilized/image_raw", 5);
  debug_pub_ = it_->advertise("debug_image", 2);
  landmarks_pub_ = nh_.advertise<steadiface::FaceLandmarks>("face_landmarks", 10);
  state_pub_ = nh_.advertise<steadiface::StabilizerState>("state", 10);
  head_target_pub_ = nh_.advertise<geometry_msgs::PointStamped>("head_target", 10);
  frusta_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("frusta", 2);
}

void StabilizerRos::StartDiagnostics() {
  updater_.reset(new diagnostic_updater::Updater(nh_, pnh_, name_));
  updater_->setHardwareID("steadiface");
  if (wrapper_options_.expected_image_rate > 0) {
    image_min_rate_ = 0.8 * wrapper_options_.expected_image_rate;
    image_max_rate_ = 1.2 * wrapper_options_.expected_image_rate;
  }
  if (wrapper_options_.expected_imu_rate > 0) {
    imu_min_rate_ = 0.8 * wrapper_options_.expected_imu_rate;
    imu_max_rate_ = 1.2 * wrapper_options_.expected_imu_rate;
  }
  image_freq_.reset(new diagnostic_updater::FrequencyStatus(
      diagnostic_updater::FrequencyStatusParam(&image_min_rate_, &image_max_rate_, 0.1, 10),
      "image input rate"));
  imu_freq_.reset(new diagnostic_updater::FrequencyStatus(
      diagnostic_updater::FrequencyStatusParam(&imu_min_rate_, &imu_max_rate_, 0.1, 10),
      "imu input rate"));
  updater_->add(*image_freq_);
  updater_->add(*imu_freq_);
  updater_->add("gyro", this, &StabilizerRos::DiagGyro);
  updater_->add("rotation source", this, &StabilizerRos::DiagRotationSource);
  updater_->add("view", this, &StabilizerRos::DiagView);
  updater_->add("face", this, &StabilizerRos::DiagFace);
  updater_->add("solver", this, &StabilizerRos::DiagSolver);
  updater_->add("frames", this, &StabilizerRos::DiagFrames);
  updater_->add("protrusion", this, &StabilizerRos::DiagProtrusion);
  updater_->add("gyro vs video", this, &StabilizerRos::DiagGyroVideo);
  updater_->add("IMU extrinsics", this, &StabilizerRos::DiagExtrinsics);
}

// Subscribes the inputs; returns the image transport in use (and whether
// the built-in jpeg/png decoder serves "compressed").
std::string StabilizerRos::Subscribe(bool* builtin_compressed_out) {
  imu_sub_ = nh_.subscribe("imu", 2000, &StabilizerRos::OnImu, this,
                           ros::TransportHints().tcpNoDelay());
  // ~image_transport (raw | compressed; LoadOptions refused anything else).
  // Debian 12 ships no compressed_image_transport plugin: without it,
  // "compressed" subscribes to image_raw/compressed and decodes with the
  // built-in jpeg/png decoder.
  const std::string& transport = wrapper_options_.image_transport;
  bool plugin = transport == "raw";
  for (const std::string& t : it_->getLoadableTransports()) {
    plugin = plugin || t == transport || t == "image_transport/" + transport;
  }
  const bool builtin_compressed = !plugin && transport == "compressed";
  const image_transport::TransportHints hints(builtin_compressed ? "raw" : transport,
                                              ros::TransportHints(), pnh_);
  if (builtin_compressed) {
    std::string why;
    if (!LoadImageDecoder(&why)) {
      ROS_ERROR("[%s] image_transport 'compressed': %s; every compressed frame will be "
                "skipped",
                name_.c_str(), why.c_str());
    }
    compressed_sub_ = nh_.subscribe("image_raw/compressed", 5, &StabilizerRos::OnCompressed, this);
    info_sub_ = nh_.subscribe("camera_info", 5, &StabilizerRos::OnCameraInfo, this);
  } else if (info_source_->has_file_info()) {
    image_only_sub_ = it_->subscribe("image_raw", 5, &StabilizerRos::OnImageOnly, this, hints);
    info_sub_ = nh_.subscribe("camera_info", 5, &StabilizerRos::OnCameraInfo, this);
  } else {
    image_sub_ = it_->subscribeCamera("image_raw", 5, &StabilizerRos::OnImage, this, hints);
  }
  if (pipeline_options_.landmark_source == steadiface::LandmarkSource::kExternal) {
    landmarks_sub_ = nh_.subscribe("landmarks_in", 10, &StabilizerRos::OnLandmarks, this);
  }
  *builtin_compressed_out = builtin_compressed;
  return transport;
}

StabilizerRos::~StabilizerRos() {
  // Stop the inputs first so nothing calls into a half-destroyed object.
  timer_.stop();
  image_sub_.shutdown();
  image_only_sub_.shutdown();
  compressed_sub_.shutdown();
  info_sub_.shutdown();
  imu_sub_.shutdown();
  landmarks_sub_.shutdown();
  reconfigure_.reset();
}

void StabilizerRos::OnImage(const sensor_msgs::ImageConstPtr& image,
                            const sensor_msgs::CameraInfoConstPtr& info) {
  image_freq_->tick();
  wrapper_->OnImage(image, info, ros::Time::now());
}

void StabilizerRos::OnImageOnly(const sensor_msgs::ImageConstPtr& image) {
  image_freq_->tick();
  sensor_msgs::CameraInfoConstPtr from_message;
  if (latest_info_ &&
      std::abs((latest_info_->header.stamp - image->header.stamp).toSec()) <= 0.5) {
    from_message = latest_info_;
  }
  // Null (size mismatch, reported by the source): the wrapper counts the
  // frame as dropped for its camera_info.
  wrapper_->OnImage(image, info_source_->Select(*image, from_message), ros::Time::now());
}

void StabilizerRos::OnCompressed(const sensor_msgs::CompressedImageConstPtr& msg) {
  sensor_msgs::ImagePtr image;
  const steadiface::Status s = FromCompressedImage(*msg, &image);
  if (!s.ok()) {
    ++decode_failures_;
    image_freq_->tick();
    Error("compressed", s.message() + " (frame skipped; " + std::to_string(decode_failures_) +
                            " so far)");
    return;
  }
  OnImageOnly(image);
}

void StabilizerRos::OnCameraInfo(const sensor_msgs::CameraInfoConstPtr& info) {
  latest_info_ = info;
}

void StabilizerRos::OnImu(const sensor_msgs::ImuConstPtr& msg) {
  imu_freq_->tick();
  imu_seen_ = true;
  last_imu_wall_ = ros::WallTime::now();
  wrapper_->OnImu(*msg);
}

void StabilizerRos::OnLandmarks(const steadiface::FaceLandmarksConstPtr& msg) {
  wrapper_->OnLandmarks(*msg);
}

void StabilizerRos::OnTimer(const ros::TimerEvent&) {
  wrapper_->OnTimer(ros::Time::now());
  updater_->update();
}

void StabilizerRos::OnReconfigure(steadiface::SteadifaceConfig& config, uint32_t) {
  // Only assigns: the wrapper applies it on the next frame.
  steadiface::PipelineOptions o = wrapper_->pipeline_options();
  ApplyConfig(config, &o);
  wrapper_->RequestStabilizerOptions(o.stabilizer);
  wrapper_->RequestLayering(o.warp.mode, o.warp.layered);
}

bool StabilizerRos::LookupExtrinsic(const std::string& imu_frame,
                                    const std::string& camera_frame, Eigen::Quaterniond* q) {
  try {
    // Rotation taking IMU-frame vectors into the camera frame.
    const geometry_msgs::TransformStamped t =
        tf_buffer_->lookupTransform(camera_frame, imu_frame, ros::Time(0));  // no wait: tried again next frame
    const auto& r = t.transform.rotation;
    Eigen::Quaterniond e(r.w, r.x, r.y, r.z);
    if (!(e.norm() > 0.5)) return false;
    *q = e.normalized();
    ROS_INFO("[%s] IMU->camera rotation from TF (%s -> %s)", name_.c_str(), imu_frame.c_str(),
             camera_frame.c_str());
    return true;
  } catch (const tf2::TransformException&) {
    return false;
  }
}

void StabilizerRos::PublishImage(const sensor_msgs::ImagePtr& image,
                                 const sensor_msgs::CameraInfoPtr& info) {
  image_pub_.publish(image, info);
}
void StabilizerRos::PublishLandmarks(const steadiface::FaceLandmarks& msg) {
  landmarks_pub_.publish(msg);
}
void StabilizerRos::PublishState(const steadiface::StabilizerState& msg) { state_pub_.publish(msg); }
void StabilizerRos::PublishTf(const std::vector<geometry_msgs::TransformStamped>& tf) {
  if (!tf.empty()) tf_broadcaster_.sendTransform(tf);
}
void StabilizerRos::PublishHeadTarget(const geometry_msgs::PointStamped& p) {
  head_target_pub_.publish(p);
}
bool StabilizerRos::WantsMarkers() const { return frusta_pub_.getNumSubscribers() > 0; }
void StabilizerRos::PublishMarkers(const visualization_msgs::MarkerArray& m) {
  frusta_pub_.publish(m);
}
bool StabilizerRos::WantsDebugImage() const { return debug_pub_.getNumSubscribers() > 0; }
void StabilizerRos::PublishDebugImage(const sensor_msgs::ImagePtr& image) {
  debug_pub_.publish(image);
}
void StabilizerRos::Warn(const std::string& key, const std::string& text) {
  ROS_WARN_STREAM_THROTTLE_NAMED(5.0, key, "[" << name_ << "] " << text);
}
void StabilizerRos::Error(const std::string& key, const std::string& text) {
  ROS_ERROR_STREAM_THROTTLE_NAMED(5.0, key, "[" << name_ << "] " << text);
}

void StabilizerRos::OnTimeJump() {
  // The wrapper's callbacks run on the subscriber threads; tf2's buffer is
  // thread-safe.
  tf_buffer_->clear();
}

void StabilizerRos::DiagGyro(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const WrapperStatus w = wrapper_->CurrentStatus();
  const double since = (ros::WallTime::now() - last_imu_wall_).toSec();
  s.add("imu messages", w.counters.imu_in);
  s.add("imu rejected", w.counters.imu_rejected);
  s.add("imu gaps", w.counters.imu_gaps);
  s.add("seconds since imu", since);
  s.add("gyro latency past last row [s]", w.gyro_latency_s);
  s.add("frames with extrapolated gyro", w.counters.extrapolated);
  s.add("frames passed through without imu", w.counters.passthrough);
  s.add("time jumps", w.counters.time_jumps);
  for (size_t i = 1; i < w.timeline.samples.size(); ++i) {
    s.add(std::string("rejected ") +
              steadiface::SampleResultName(static_cast<steadiface::SampleResult>(i)),
          w.timeline.samples[i]);
  }
  const bool auto_source = w.rotation_source == "auto";
  const std::string instead =
      auto_source ? ": the rotation comes from the video" : ": frames are not stabilized";
  s.add("frames rotated from the video", w.counters.from_video);
  if (w.rotation_source == "visual") {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK,
              "not used: rotation_source is visual (see \"rotation source\")");
  } else if (!imu_seen_ && since > wrapper_options_.scheduler.imu_timeout_s) {
    s.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "no IMU data" + instead);
  } else if (since > wrapper_options_.scheduler.imu_timeout_s) {
    s.summary(diagnostic_msgs::DiagnosticStatus::ERROR, "IMU stopped" + instead);
  } else if (w.counters.imu_rejected > 0 || w.counters.imu_gaps > 0 || w.counters.extrapolated > 0) {
    s.summary(diagnostic_msgs::DiagnosticStatus::WARN,
              "IMU rejects, gaps or extrapolated frames (see values)");
  } else {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, "gyro covers every frame");
  }
}

void StabilizerRos::DiagRotationSource(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const WrapperStatus w = wrapper_->CurrentStatus();
  s.add("rotation_source", w.rotation_source);
  s.add("frames rotated from the video", w.counters.from_video);
  if (w.rotation_source == "imu" || (w.rotation_source == "auto" && !w.last_from_video)) {
    s.add("source", "imu");
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, "imu");
    return;
  }
  s.add("source", "visual");
  s.add("tracked features", w.visual.tracked);
  s.add("inliers", w.visual.inliers);
  s.add("residual [px]", w.visual.residual_px);
  s.add("turn standard error [px]", w.visual.turn_error_px);
  s.add("time [ms]", w.visual.ms);
  const std::string what = w.rotation_source == "auto" ? "visual (no IMU data)" : "visual";
  if (!w.pipeline_ready) {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, what + ": waiting for the first image");
  } else if (w.visual.valid) {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, what);
  } else {
    s.summary(diagnostic_msgs::DiagnosticStatus::WARN,
              what + ": too few features fit one rotation (texture, darkness, a crowd); "
                     "holding the camera still");
  }
}

void StabilizerRos::DiagView(diagnostic_updater::DiagnosticStatusWrapper& s) {
  // The crop and the level horizon as of the last frame.
  const WrapperStatus w = wrapper_->CurrentStatus();
  const double deg = 180.0 / M_PI;
  s.add("crop", w.crop.dynamic ? "dynamic" : "fixed");
  s.add("kept width", 1.0 - 2.0 * w.crop.crop_ratio);
  s.add("crop target", w.crop.target);
  s.add("horizon", w.horizon_mode);
  s.add("accelerometer readings taken", w.accel_accepted);
  s.add("accelerometer readings left out", w.accel_rejected);
  s.add("output roll [deg]", w.horizon.output_roll_rad * deg);
  s.add("camera roll [deg]", w.horizon.real_roll_rad * deg);
  std::ostringstream what;
  what << "kept width " << std::fixed << std::setprecision(2) << 1.0 - 2.0 * w.crop.crop_ratio
       << (w.crop.dynamic ? " (dynamic)" : "") << "; horizon " << w.horizon_mode;
  if (w.horizon_mode == "off" || !w.pipeline_ready) {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, what.str());
  } else if (w.horizon.active) {
    what << ", output roll " << std::setprecision(1) << w.horizon.output_roll_rad * deg
         << " deg (camera " << w.horizon.real_roll_rad * deg << " deg)";
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, what.str());
  } else {
    what << " inactive: "
         << (w.horizon.inactive_reason == "visual rotation"
                 ? "the rotation comes from the video; the roll is kept as without a horizon"
                 : w.accel_accepted + w.accel_rejected == 0
                       ? "no accelerometer readings in the IMU messages"
                       : "gravity not known yet (readings far from 1 g are left out)");
    s.summary(diagnostic_msgs::DiagnosticStatus::WARN, what.str());
  }
  if (!w.view_conflict.empty()) {
    s.mergeSummary(diagnostic_msgs::DiagnosticStatus::WARN, w.view_conflict);
  }
}

void StabilizerRos::DiagExtrinsics(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const WrapperStatus w = wrapper_->CurrentStatus();
  using E = ExtrinsicsState;
  const std::string tf = "TF " + w.extrinsics_from + " -> " + w.extrinsics_to;
  s.add("imu frame", w.extrinsics_from);
  s.add("camera frame", w.extrinsics_to);
  switch (w.extrinsics) {
    case E::kConfigured:
      s.summary(diagnostic_msgs::DiagnosticStatus::OK, "from imu/R_cam_imu");
      break;
    case E::kWaitingForImu:
      s.summary(diagnostic_msgs::DiagnosticStatus::OK, "waiting for the first IMU message");
      break;
    case E::kSameFrame:
      s.summary(diagnostic_msgs::DiagnosticStatus::OK, "IMU and camera share a frame");
      break;
    case E::kWaitingForTf:
      s.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                "no " + tf + " yet: using imu/R_cam_imu until it comes");
      break;
    case E::kFromTf:
      s.summary(diagnostic_msgs::DiagnosticStatus::OK, "from " + tf);
      break;
  }
}

void StabilizerRos::DiagFace(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const WrapperStatus w = wrapper_->CurrentStatus();
  s.add("state", steadiface::TrackingStateName(w.face_state));
  s.add("failure", w.face_failure);
  s.add("confidence", w.face_confidence);
  s.add("landmarks_in rejected", w.counters.landmarks_bad);
  if (!w.landmark_model_error.empty()) {
    s.summary(diagnostic_msgs::DiagnosticStatus::ERROR,
              "no landmark model, gyro-only: " + w.landmark_model_error);
  } else if (pipeline_options_.landmark_source == steadiface::LandmarkSource::kNone) {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, "face processing off (gyro-only)");
  } else if (w.face_state == steadiface::TrackingState::kLost) {
    s.summary(diagnostic_msgs::DiagnosticStatus::WARN,
              "face of interest lost (" + w.face_failure + "): fading to gyro-only");
  } else if (w.face_state == steadiface::TrackingState::kTracking) {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, "tracking the face of interest");
  } else {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, "no face: gyro-only stabilization");
  }
}

void StabilizerRos::DiagSolver(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const WrapperStatus w = wrapper_->CurrentStatus();
  s.add("last termination", w.last_solver_termination);
  s.add("last iterations", w.last_solver_iterations);
  s.add("last time [ms]", w.last_solver_ms);
  s.add("failures (previous solution kept)", w.stabilizer.solver_failures);
  s.add("reruns (time cap ran out before the first step)", w.stabilizer.solver_restarts);
  s.add("frames", w.stabilizer.frames);
  if (w.stabilizer.solver_failures > reported_solver_failures_) {
    s.summary(diagnostic_msgs::DiagnosticStatus::WARN, "solver failed; previous solution kept");
  } else {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, "solver healthy");
  }
  reported_solver_failures_ = w.stabilizer.solver_failures;
}

void StabilizerRos::DiagFrames(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const WrapperStatus w = wrapper_->CurrentStatus();
  const WrapperCounters& c = w.counters;
  s.add("images in", c.images_in);
  s.add("frames out", c.frames_out);
  s.add("dropped: bad image", c.dropped_bad_image);
  s.add("dropped: bad camera_info", c.dropped_bad_info);
  s.add("dropped: no gyro", c.dropped_no_gyro);
  s.add("dropped: queue full", c.dropped_queue_full);
  s.add("dropped: old stamp", c.dropped_old_stamp);
  s.add("dropped: refused", c.dropped_pipeline_error);
  s.add("withheld: the video's first frame", c.withheld);
  s.add("geometry rebuilds", c.rebuilds);
  s.add("last error", w.last_error);
  const uint64_t drops = c.dropped_bad_image + c.dropped_bad_info + c.dropped_no_gyro +
                         c.dropped_queue_full + c.dropped_old_stamp + c.dropped_pipeline_error;
  if (drops > reported_drops_) {
    s.summary(diagnostic_msgs::DiagnosticStatus::WARN, "frames dropped: " + w.last_error);
  } else {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, "no frames dropped since last report");
  }
  reported_drops_ = drops;
}

void StabilizerRos::DiagProtrusion(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const WrapperStatus w = wrapper_->CurrentStatus();
  s.add("binary searches", w.stabilizer.protrusion_searches);
  s.add("previous-warp fallbacks", w.stabilizer.previous_warp_fallbacks);
  s.add("frames with undefined pixels", w.stabilizer.undefined_frames);
  const uint64_t f = w.stabilizer.previous_warp_fallbacks + w.stabilizer.undefined_frames;
  if (f > reported_fallbacks_) {
    s.summary(diagnostic_msgs::DiagnosticStatus::WARN, "previous warp reused (no valid pose)");
  } else {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, "no protrusion fallback");
  }
  reported_fallbacks_ = f;
}

void StabilizerRos::DiagGyroVideo(diagnostic_updater::DiagnosticStatusWrapper& s) {
  const WrapperStatus w = wrapper_->CurrentStatus();
  const steadiface::GyroVideoCheckResult& c = w.gyro_video_check;
  const Eigen::Quaterniond& q = c.best_R_cam_imu;
  char quat[96];
  std::snprintf(quat, sizeof(quat), "[%.3f, %.3f, %.3f, %.3f]", q.x(), q.y(), q.z(), q.w());
  s.add("judged", c.judged);
  s.add("frame pairs in window", c.pairs);
  s.add("feature motion per pair [px]", c.motion_px);
  s.add("residual with imu/R_cam_imu [px]", c.residual_configured_px);
  s.add("residual with the best axis permutation [px]", c.residual_best_mounting_px);
  s.add("best axis permutation as imu/R_cam_imu [x y z w]", std::string(quat));
  s.add("imu/time_offset correction [ms]", c.offset_correction_s * 1e3);
  s.add("correction applied now [ms]", w.imu_offset_applied_s * 1e3);
  char text[512];
  // What the node does about an offset it disagrees with.
  char applying[160] = "";
  if (pipeline_options_.gyro_video_check.apply_offset) {
    std::snprintf(applying, sizeof(applying),
                  "; applying %+.1f ms now (gyro_video_check/apply_offset, at most %.0f ms/s)",
                  w.imu_offset_applied_s * 1e3,
                  pipeline_options_.gyro_video_check.apply_rate_s_per_s * 1e3);
  }
  if (!pipeline_options_.gyro_video_check.enabled) {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, "check off (gyro_video_check/enabled)");
  } else if (w.rotation_source == "visual") {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK,
              "not used: rotation_source is visual (no gyro to check)");
  } else if (w.last_from_video && !c.judged) {
    s.summary(diagnostic_msgs::DiagnosticStatus::OK,
              "not checked while the rotation comes from the video (no IMU data)");
  } else if (!c.judged) {
    std::snprintf(text, sizeof(text),
                  "not enough image motion yet to judge (%d frame pairs, %.1f px)", c.pairs,
                  c.motion_px);
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, text);
  } else if (c.rotation_contradicts) {
    std::snprintf(text, sizeof(text),
                  "imu/R_cam_imu contradicts the video: the gyro predicts the background's "
                  "motion to %.1f px, the axis permutation %s to %.1f px (of %.1f px motion); "
                  "set imu/R_cam_imu: %s and add %+.1f ms to imu/time_offset",
                  c.residual_configured_px, quat, c.residual_best_mounting_px, c.motion_px, quat,
                  c.offset_correction_s * 1e3);
    s.summary(diagnostic_msgs::DiagnosticStatus::WARN, text);
  } else if (c.offset_off) {
    std::snprintf(text, sizeof(text),
                  "imu/time_offset is off by %+.1f ms: the video agrees best with imu/time_offset "
                  "%+.1f ms (%.4f s)%s",
                  c.offset_correction_s * 1e3, c.offset_correction_s * 1e3,
                  pipeline_options_.imu.imu_time_offset_s + c.offset_correction_s, applying);
    s.summary(diagnostic_msgs::DiagnosticStatus::WARN, text);
  } else {
    std::snprintf(text, sizeof(text),
                  "gyro agrees with the video (residual %.2f px of %.1f px motion, offset within "
                  "%.0f ms)",
                  c.residual_configured_px, c.motion_px,
                  pipeline_options_.gyro_video_check.offset_warn_s * 1e3);
    s.summary(diagnostic_msgs::DiagnosticStatus::OK, text);
  }
}

}  // namespace steadiface_ros

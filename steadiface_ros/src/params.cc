#include "steadiface_ros/params.h"

#include <cmath>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "steadiface_ros/resource_url.h"

namespace steadiface_ros {
namespace {

using steadiface::Status;

class RosParamSource : public ParamSource {
 public:
  explicit RosParamSource(const ros::NodeHandle& nh) : nh_(nh) {}
  bool Get(const std::string& k, double* v) const override { return nh_.getParam(k, *v); }
  bool Get(const std::string& k, int* v) const override { return nh_.getParam(k, *v); }
  bool Get(const std::string& k, bool* v) const override { return nh_.getParam(k, *v); }
  bool Get(const std::string& k, std::string* v) const override { return nh_.getParam(k, *v); }
  bool Get(const std::string& k, std::vector<double>* v) const override {
    return nh_.getParam(k, *v);
  }

 private:
  ros::NodeHandle nh_;
};

class YamlParamSource : public ParamSource {
 public:
  explicit YamlParamSource(std::vector<YAML::Node> docs) : docs_(std::move(docs)) {}

  template <typename T>
  bool GetT(const std::string& key, T* v) const {
    // Later documents override earlier ones.
    for (auto it = docs_.rbegin(); it != docs_.rend(); ++it) {
      YAML::Node n;
      if (!Lookup(*it, key, &n) || n.IsNull()) continue;
      try {
        *v = n.as<T>();
        return true;
      } catch (const YAML::Exception&) {
        return false;
      }
    }
    return false;
  }
  bool Get(const std::string& k, double* v) const override { return GetT(k, v); }
  bool Get(const std::string& k, int* v) const override { return GetT(k, v); }
  bool Get(const std::string& k, bool* v) const override { return GetT(k, v); }
  bool Get(const std::string& k, std::string* v) const override { return GetT(k, v); }
  bool Get(const std::string& k, std::vector<double>* v) const override { return GetT(k, v); }

 private:
  // Walks '/'-separated `key` through nested maps without modifying them.
  static bool Lookup(const YAML::Node& root, const std::string& key, YAML::Node* out) {
    const YAML::Node* cur = &root;
    YAML::Node holder;
    std::stringstream ss(key);
    std::string part;
    while (std::getline(ss, part, '/')) {
      if (!cur->IsMap()) return false;
      const YAML::Node& c = *cur;
      const YAML::Node child = c[part];  // const operator[]: no insertion
      if (!child.IsDefined()) return false;
      holder.reset(child);
      cur = &holder;
    }
    *out = *cur;
    return true;
  }
  std::vector<YAML::Node> docs_;
};

// Reads `key` if present; checks [lo, hi]. Records the first error.
class Reader {
 public:
  explicit Reader(const ParamSource& p) : p_(p) {}
  void Num(const std::string& key, double* v, double lo, double hi) {
    double x = *v;
    if (!p_.Get(key, &x)) {
      int i;
      if (p_.Get(key, &i)) x = i;
    }
    if (!std::isfinite(x) || x < lo || x > hi) {
      Fail(key, x, lo, hi);
      return;
    }
    *v = x;
  }
  void Int(const std::string& key, int* v, int lo, int hi) {
    int x = *v;
    p_.Get(key, &x);
    if (x < lo || x > hi) {
      Fail(key, x, lo, hi);
      return;
    }
    *v = x;
  }
  void Bool(const std::string& key, bool* v) { p_.Get(key, v); }
  void Str(const std::string& key, std::string* v) { p_.Get(key, v); }
  // A file parameter: a plain path, file:// or package:// (ResolveResourceUrl).
  void Path(const std::string& key, std::string* v) {
    std::string url = *v;
    p_.Get(key, &url);
    if (url.empty()) {
      *v = url;
      return;
    }
    const Status s = ResolveResourceUrl("parameter '" + key + "'", url, v);
    if (!s.ok()) Error(s.message());
  }
  void Vec(const std::string& key, std::vector<double>* v) { p_.Get(key, v); }
  void Error(const std::string& msg) {
    if (error_.empty()) error_ = msg;
  }
  Status status() const { return error_.empty() ? Status::Ok() : Status::Error(error_); }

 private:
  void Fail(const std::string& key, double x, double lo, double hi) {
    std::ostringstream e;
    e << "parameter '" << key << "' = " << x << " is out of range [" << lo << ", " << hi
      << "]";
    Error(e.str());
  }
  const ParamSource& p_;
  std::string error_;
};

}  // namespace

std::unique_ptr<ParamSource> RosParams(const ros::NodeHandle& nh) {
  return std::unique_ptr<ParamSource>(new RosParamSource(nh));
}

Status YamlParams(const std::vector<std::string>& paths, std::unique_ptr<ParamSource>* out) {
  std::vector<YAML::Node> docs;
  for (const auto& p : paths) {
    try {
      docs.push_back(YAML::LoadFile(p));
    } catch (const YAML::Exception& e) {
      return Status::Error("cannot read parameters '" + p + "': " + e.what());
    }
  }
  out->reset(new YamlParamSource(std::move(docs)));
  return Status::Ok();
}

Status LoadOptions(const ParamSource& params, steadiface::PipelineOptions* po,
                   WrapperOptions* wo) {
  using namespace steadiface;  // NOLINT (source file, not a header)
  Reader r(params);
  // ROS layer.
  r.Str("camera_frame", &wo->camera_frame);
  r.Str("camera_info_url", &wo->camera_info_url);
  r.Str("stabilized_suffix", &wo->stabilized_suffix);
  r.Str("world_frame", &wo->world_frame);
  r.Bool("publish_world_tf", &wo->publish_world_tf);
  r.Bool("imu_extrinsics_from_tf", &wo->imu_extrinsics_from_tf);
  r.Num("max_gyro_wait", &wo->scheduler.max_gyro_wait_s, 0.0, 5.0);
  std::string policy = wo->scheduler.late_frame_policy == steadiface::LateFramePolicy::kDrop ? "drop" : "extrapolate";
  r.Str("late_frame_policy", &policy);
  if (policy == "drop") {
    wo->scheduler.late_frame_policy = steadiface::LateFramePolicy::kDrop;
  } else if (policy == "extrapolate") {
    wo->scheduler.late_frame_policy = steadiface::LateFramePolicy::kExtrapolate;
  } else {
    r.Error("parameter 'late_frame_policy' must be 'extrapolate' or 'drop', got '" + policy + "'");
  }
  r.Int("frame_queue_size", &wo->scheduler.frame_queue_size, 1, 1000);
  r.Num("imu_timeout", &wo->scheduler.imu_timeout_s, 0.01, 60.0);
  r.Num("imu_gap_warn", &wo->scheduler.imu_gap_warn_s, 0.001, 10.0);
  r.Num("expected_image_rate", &wo->expected_image_rate, 0.0, 1000.0);
  r.Num("expected_imu_rate", &wo->expected_imu_rate, 0.0, 100000.0);
  r.Bool("passthrough_without_imu", &wo->passthrough_without_imu);
  r.Bool("pipelined", &wo->pipelined);
  r.Num("pipeline_hold", &wo->scheduler.pipeline_hold_s, 0.0, 1.0);
  std::string source = po->landmark_source == LandmarkSource::kExternal
                           ? "topic"
                           : po->landmark_source == LandmarkSource::kNone ? "none" : "dlib";
  r.Str("landmark_source", &source);
  if (source == "dlib") {
    po->landmark_source = LandmarkSource::kDlib;
  } else if (source == "topic") {
    po->landmark_source = LandmarkSource::kExternal;
  } else if (source == "none") {
    po->landmark_source = LandmarkSource::kNone;
  } else {
    r.Error("parameter 'landmark_source' must be 'dlib', 'topic' or 'none', got '" + source + "'");
  }
  // Camera.
  r.Num("camera/readout_time", &po->shutter.readout_time_s, 0.0, 0.2);
  std::string stamp = "first_row";
  r.Str("camera/stamp", &stamp);
  if (stamp == "first_row") {
    po->shutter.stamp = StampConvention::kFirstRow;
  } else if (stamp == "middle_row") {
    po->shutter.stamp = StampConvention::kMiddleRow;
  } else if (stamp == "last_row") {
    po->shutter.stamp = StampConvention::kLastRow;
  } else {
    r.Error("parameter 'camera/stamp' must be first_row, middle_row or last_row, got '" + stamp + "'");
  }
  r.Num("camera/row_time_offset", &po->shutter.row_time_offset_s, -0.5, 0.5);
  r.Num("camera/virtual_focal_scale", &po->camera.virtual_focal_scale, 0.25, 4.0);
  // IMU.
  const Eigen::Quaterniond& q0 = po->imu.R_cam_imu;
  std::vector<double> q = {q0.x(), q0.y(), q0.z(), q0.w()};
  r.Vec("imu/R_cam_imu", &q);
  if (q.size() != 4) {
    r.Error("parameter 'imu/R_cam_imu' must be a quaternion [x, y, z, w]");
  } else {
    const Eigen::Quaterniond e(q[3], q[0], q[1], q[2]);
    if (!(e.norm() > 0.5 && e.norm() < 2.0)) {
      r.Error("parameter 'imu/R_cam_imu' must be a unit quaternion [x, y, z, w]");
    } else {
      po->imu.R_cam_imu = e.normalized();
    }
  }
  r.Num("imu/time_offset", &po->imu.imu_time_offset_s, -1.0, 1.0);
  {
    const Eigen::Vector3d& b0 = po->imu.gyro_bias;
    std::vector<double> b = {b0.x(), b0.y(), b0.z()};
    r.Vec("imu/gyro_bias", &b);
    if (b.size() != 3 || !std::isfinite(b[0]) || !std::isfinite(b[1]) || !std::isfinite(b[2]) ||
        Eigen::Vector3d(b[0], b[1], b[2]).norm() >= 1.0) {
      r.Error("parameter 'imu/gyro_bias' must be [bx, by, bz] in rad/s with |bias| < 1");
    } else {
      po->imu.gyro_bias = Eigen::Vector3d(b[0], b[1], b[2]);
    }
  }
  r.Num("imu/buffer_duration", &po->imu.buffer_duration_s, 0.5, 600.0);
  r.Int("imu/max_samples", &po->imu.max_samples, 16, 10000000);
  r.Num("imu/max_angular_rate", &po->imu.max_angular_rate, 0.1, 1000.0);
  r.Num("imu/max_gap", &po->imu.max_gap_s, 0.001, 10.0);
  r.Num("imu/max_extrapolation", &po->imu.max_extrapolation_s, 0.0, 1.0);
  // Face.
  FaceTrackerOptions& f = po->face;
  std::string det = f.detector.type == FaceDetectorType::kOpenCvCascade ? "opencv_cascade" : "dlib_hog";
  r.Str("face/detector", &det);
  if (det == "dlib_hog") {
    f.detector.type = FaceDetectorType::kDlibHog;
  } else if (det == "opencv_cascade") {
    f.detector.type = FaceDetectorType::kOpenCvCascade;
  } else {
    r.Error("parameter 'face/detector' must be dlib_hog or opencv_cascade, got '" + det + "'");
  }
  r.Int("face/detector_max_side", &f.detector.max_side_px, 64, 8192);
  // Resolved only where it is used: a package:// cascade must not stop a
  // dlib_hog run started outside a sourced workspace.
  if (f.detector.type == FaceDetectorType::kOpenCvCascade) {
    r.Path("face/cascade_path", &f.detector.cascade_path);
  } else {
    r.Str("face/cascade_path", &f.detector.cascade_path);
  }
  r.Num("face/dlib_threshold", &f.detector.dlib_threshold, -2.0, 5.0);
  r.Int("face/min_face_px", &f.detector.min_face_px, 8, 4096);
  r.Path("face/landmark_model", &f.landmark_model_path);
  r.Int("face/redetect_every", &f.redetect_every_frames, 1, 10000);
  r.Num("face/redetect_region_scale", &f.redetect_region_scale, 1.0, 10.0);
  r.Int("face/redetect_face_px", &f.redetect_face_px, 60, 1000);
  r.Num("face/lost_timeout", &f.lost_timeout_s, 0.0, 60.0);
  r.Num("face/search_interval", &f.search_interval_s, 0.0, 10.0);
  r.Num("face/max_shape_residual", &f.max_shape_residual, 0.001, 2.0);
  r.Num("face/min_spread_ratio", &f.min_spread_ratio, 0.01, 10.0);
  r.Num("face/max_spread_ratio", &f.max_spread_ratio, 0.01, 10.0);
  r.Num("face/max_jump", &f.max_jump, 0.01, 20.0);
  r.Num("face/min_appearance", &f.min_appearance, -1.0, 0.999);
  r.Bool("face/estimate_head_pose", &f.estimate_head_pose);
  // Stabilizer.
  StabilizerOptions& s = po->stabilizer;
  r.Num("head/w_stay", &s.head.w_stay, 0.0, 1e9);
  r.Num("head/w_follow", &s.head.w_follow, 0.0, 1e9);
  r.Num("head/d_ref", &s.head.d_ref, 1e-6, 1.0);
  r.Num("weights/fit", &s.weights.fit, 0.0, 1e6);
  r.Num("weights/distortion", &s.weights.distortion, 0.0, 1e6);
  r.Num("weights/follow", &s.weights.follow, 0.0, 1e6);
  r.Num("weights/rotation_c0", &s.weights.rotation_c0, 0.0, 1e6);
  r.Num("weights/rotation_c1", &s.weights.rotation_c1, 0.0, 1e6);
  r.Num("weights/translation_c0", &s.weights.translation_c0, 1e-6, 1e6);
  r.Num("weights/translation_c1", &s.weights.translation_c1, 0.0, 1e6);
  r.Num("weights/protrusion", &s.weights.protrusion, 0.0, 1e6);
  r.Num("terms/distortion_threshold", &s.terms.distortion_threshold_rad, 0.0, 1.5);
  r.Num("terms/distortion_slope", &s.terms.distortion_slope, 1.0, 1e4);
  r.Num("terms/protrusion_alpha", &s.terms.protrusion_alpha, 1e-5, 1.0);
  r.Num("terms/protrusion_shrink", &s.terms.protrusion_shrink, 0.0, 0.2);
  r.Int("terms/protrusion_samples_per_edge", &s.terms.protrusion_samples_per_edge, 2, 256);
  r.Bool("dynamic/enabled", &s.dynamic.enabled);
  r.Num("dynamic/fade_time", &s.dynamic.fade_time_s, 0.0, 10.0);
  r.Num("dynamic/gyro_window", &s.dynamic.gyro_window_s, 0.02, 10.0);
  r.Num("dynamic/gyro_still", &s.dynamic.gyro_still_rad_s, 0.0, 10.0);
  r.Num("dynamic/gyro_active", &s.dynamic.gyro_active_rad_s, 1e-6, 20.0);
  r.Num("dynamic/gyro_still_fit_scale", &s.dynamic.gyro_still_fit_scale, 0.0, 1.0);
  r.Num("dynamic/pose_low", &s.dynamic.pose_low_rad, 0.0, 1.6);
  r.Num("dynamic/pose_high", &s.dynamic.pose_high_rad, 1e-6, 3.2);
  r.Num("dynamic/pose_min_fit_scale", &s.dynamic.pose_min_fit_scale, 0.0, 1.0);
  r.Num("dynamic/pose_smoothness_boost", &s.dynamic.pose_smoothness_boost, 0.0, 100.0);
  r.Int("dynamic/variation_window", &s.dynamic.variation_window, 3, 1000);
  r.Num("dynamic/centre_variation_low", &s.dynamic.centre_variation_low, 0.0, 1.0);
  r.Num("dynamic/centre_variation_high", &s.dynamic.centre_variation_high, 1e-9, 2.0);
  r.Num("dynamic/scale_variation_low", &s.dynamic.scale_variation_low, 0.0, 10.0);
  r.Num("dynamic/scale_variation_high", &s.dynamic.scale_variation_high, 1e-9, 20.0);
  r.Num("dynamic/variation_min_fit_scale", &s.dynamic.variation_min_fit_scale, 0.0, 1.0);
  r.Int("solver/max_iterations", &s.solver.max_iterations, 1, 1000);
  r.Num("solver/function_tolerance", &s.solver.function_tolerance, 1e-16, 0.1);
  r.Num("solver/max_time", &s.solver.max_time_s, 1e-4, 10.0);
  r.Int("stabilizer/protrusion_search_steps", &s.protrusion_search_steps, 1, 60);
  r.Int("stabilizer/row_rotation_samples", &s.row_rotation_samples, 1, 4096);
  r.Num("stabilizer/min_face_confidence", &s.min_face_confidence, 0.0, 1.0);
  r.Bool("stabilizer/gyro_only", &s.gyro_only);
  r.Bool("stabilizer/background_layer", &s.background_layer);
  r.Bool("stabilizer/smooth_head_in_virtual_view", &s.smooth_head_in_virtual_view);
  r.Num("stabilizer/intentional_window", &s.intentional_window_s, 0.0, 5.0);
  r.Num("stabilizer/subject_reach", &s.subject_reach, 0.0, 10.0);
  // Output and warp.
  r.Num("output/crop_ratio", &po->warp.output.crop_ratio, 0.0, 0.4);
  r.Int("output/width", &po->warp.output.width, 0, 16384);
  r.Int("output/height", &po->warp.output.height, 0, 16384);
  r.Int("warp/mesh_cols", &po->warp.mesh_cols, 1, 512);
  r.Int("warp/mesh_rows", &po->warp.mesh_rows, 1, 512);
  r.Int("warp/num_threads", &po->warp.num_threads, 0, 256);
  r.Bool("warp/fixed_point_maps", &po->warp.fixed_point_maps);
  std::string mode = WarpModeName(po->warp.mode);
  r.Str("warp/mode", &mode);
  {
    const Status ms = ParseWarpMode(mode, &po->warp.mode);
    if (!ms.ok()) r.Error("parameter 'warp/mode': " + ms.message());
  }
  LayeredWarpOptions& lw = po->warp.layered;
  r.Int("warp/layered/mesh_cols", &lw.mesh_cols, 2, 512);
  r.Int("warp/layered/mesh_rows", &lw.mesh_rows, 2, 512);
  r.Num("warp/layered/band_width", &lw.blend.band_width, 0.02, 10.0);
  r.Num("warp/layered/band_inside", &lw.blend.band_inside, 0.0, 1.0);
  r.Num("warp/layered/outline_margin", &lw.blend.outline_margin_cells, 0.0, 4.0);
  r.Num("warp/layered/max_offset", &lw.blend.max_offset, 0.0, 10.0);
  r.Num("warp/layered/offset_lowpass", &lw.blend.offset_lowpass_hz, 0.0, 10.0);
  r.Num("warp/layered/band_data_weight", &lw.blend.band_data_weight, 1e-6, 1.0);
  r.Num("warp/layered/shape_weight", &lw.blend.shape_weight, 0.0, 1e4);
  r.Num("warp/layered/temporal_weight", &lw.blend.temporal_weight, 0.0, 1e4);
  r.Num("warp/layered/min_cell_ratio", &lw.blend.min_cell_ratio, 0.0, 0.99);
  r.Bool("warp/layered/yield_to_subject", &lw.blend.yield_to_subject);
  r.Num("warp/layered/head_width_scale", &lw.region.head_width_scale, 0.2, 5.0);
  r.Num("warp/layered/head_top_scale", &lw.region.head_top_scale, 0.0, 3.0);
  r.Bool("warp/layered/torso", &lw.region.torso);
  r.Num("warp/layered/shoulder_width_scale", &lw.region.shoulder_width_scale, 0.2, 10.0);
  r.Num("warp/layered/neck_width_scale", &lw.region.neck_width_scale, 0.05, 5.0);
  r.Num("warp/layered/region_smoothing", &lw.region.smoothing_s, 0.0, 10.0);
  r.Num("warp/layered/ramp", &lw.region.ramp_s, 0.01, 60.0);
  // The gyro-vs-video check.
  GyroVideoCheckOptions& c = po->gyro_video_check;
  r.Bool("gyro_video_check/enabled", &c.enabled);
  r.Int("gyro_video_check/stride", &c.stride, 1, 100);
  r.Int("gyro_video_check/track_width", &c.track_width, 64, 4096);
  r.Int("gyro_video_check/max_features", &c.max_features, 8, 2000);
  r.Num("gyro_video_check/max_fb_error", &c.max_fb_error_px, 1e-3, 10.0);
  r.Num("gyro_video_check/window", &c.window_s, 0.5, 60.0);
  r.Num("gyro_video_check/offset_range", &c.offset_range_s, 0.0, 0.5);
  r.Num("gyro_video_check/offset_step", &c.offset_step_s, 0.0005, 0.1);
  r.Int("gyro_video_check/min_pairs", &c.min_pairs, 2, 100000);
  r.Num("gyro_video_check/min_motion", &c.min_motion_px, 0.0, 1000.0);
  r.Num("gyro_video_check/better_mounting_ratio", &c.better_mounting_ratio, 0.01, 0.99);
  r.Num("gyro_video_check/offset_warn", &c.offset_warn_s, 1e-4, 1.0);
  r.Bool("gyro_video_check/apply_offset", &c.apply_offset);
  r.Num("gyro_video_check/apply_rate", &c.apply_rate_s_per_s, 1e-5, 1.0);
  Status st = r.status();
  if (!st.ok()) return st;
  // Cross-field checks of the core (e.g. low < high) with its own messages.
  return ValidatePipelineOptions(*po);
}

void ApplyConfig(const steadiface::SteadifaceConfig& c, steadiface::StabilizerOptions* o) {
  o->weights.fit = c.w_fit;
  o->weights.distortion = c.w_distortion;
  o->weights.follow = c.w_follow;
  o->weights.rotation_c0 = c.w_rotation_c0;
  o->weights.rotation_c1 = c.w_rotation_c1;
  o->weights.translation_c0 = c.w_translation_c0;
  o->weights.translation_c1 = c.w_translation_c1;
  o->weights.protrusion = c.w_protrusion;
  o->terms.distortion_threshold_rad = c.distortion_threshold;
  o->terms.distortion_slope = c.distortion_slope;
  o->terms.protrusion_alpha = c.protrusion_alpha;
  o->terms.protrusion_shrink = c.protrusion_shrink;
  o->head.w_stay = c.head_w_stay;
  o->head.w_follow = c.head_w_follow;
  o->head.d_ref = c.head_d_ref;
  o->dynamic.enabled = c.dynamic_enabled;
  o->dynamic.fade_time_s = c.fade_time;
  o->dynamic.gyro_still_rad_s = c.gyro_still;
  o->dynamic.gyro_active_rad_s = std::max(c.gyro_active, c.gyro_still + 1e-4);
  o->dynamic.pose_low_rad = c.pose_low;
  o->dynamic.pose_high_rad = std::max(c.pose_high, c.pose_low + 1e-3);
  o->dynamic.gyro_window_s = c.gyro_window;
  o->dynamic.gyro_still_fit_scale = c.gyro_still_fit_scale;
  o->dynamic.pose_min_fit_scale = c.pose_min_fit_scale;
  o->dynamic.pose_smoothness_boost = c.pose_smoothness_boost;
  o->dynamic.centre_variation_low = c.centre_variation_low;
  o->dynamic.centre_variation_high = std::max(c.centre_variation_high, c.centre_variation_low + 1e-6);
  o->dynamic.scale_variation_low = c.scale_variation_low;
  o->dynamic.scale_variation_high = std::max(c.scale_variation_high, c.scale_variation_low + 1e-6);
  o->dynamic.variation_min_fit_scale = c.variation_min_fit_scale;
  o->gyro_only = c.gyro_only;
  o->min_face_confidence = c.min_face_confidence;
  o->protrusion_search_steps = c.protrusion_search_steps;
  o->solver.max_iterations = c.solver_max_iterations;
  o->smooth_head_in_virtual_view = c.smooth_head_in_virtual_view;
}

void ApplyConfig(const steadiface::SteadifaceConfig& c, steadiface::WarpMode* mode,
                 steadiface::LayeredWarpOptions* layered) {
  steadiface::WarpMode m;
  if (steadiface::ParseWarpMode(c.warp_mode, &m).ok()) *mode = m;
  layered->blend.band_width = c.band_width;
  layered->blend.band_inside = c.band_inside;
  layered->blend.outline_margin_cells = c.outline_margin;
  layered->blend.max_offset = c.max_offset;
  layered->blend.offset_lowpass_hz = c.offset_lowpass;
  layered->blend.yield_to_subject = c.yield_to_subject;
  layered->region.head_width_scale = c.head_width_scale;
  layered->region.head_top_scale = c.head_top_scale;
  layered->region.torso = c.torso;
  layered->region.shoulder_width_scale = c.shoulder_width_scale;
}

steadiface::SteadifaceConfig ConfigFromOptions(const steadiface::StabilizerOptions& o,
                                               const steadiface::WarpOptions& w) {
  steadiface::SteadifaceConfig c = steadiface::SteadifaceConfig::__getDefault__();
  c.w_fit = o.weights.fit;
  c.w_distortion = o.weights.distortion;
  c.w_follow = o.weights.follow;
  c.w_rotation_c0 = o.weights.rotation_c0;
  c.w_rotation_c1 = o.weights.rotation_c1;
  c.w_translation_c0 = o.weights.translation_c0;
  c.w_translation_c1 = o.weights.translation_c1;
  c.w_protrusion = o.weights.protrusion;
  c.distortion_threshold = o.terms.distortion_threshold_rad;
  c.distortion_slope = o.terms.distortion_slope;
  c.protrusion_alpha = o.terms.protrusion_alpha;
  c.protrusion_shrink = o.terms.protrusion_shrink;
  c.head_w_stay = o.head.w_stay;
  c.head_w_follow = o.head.w_follow;
  c.head_d_ref = o.head.d_ref;
  c.dynamic_enabled = o.dynamic.enabled;
  c.fade_time = o.dynamic.fade_time_s;
  c.gyro_still = o.dynamic.gyro_still_rad_s;
  c.gyro_active = o.dynamic.gyro_active_rad_s;
  c.pose_low = o.dynamic.pose_low_rad;
  c.pose_high = o.dynamic.pose_high_rad;
  c.gyro_window = o.dynamic.gyro_window_s;
  c.gyro_still_fit_scale = o.dynamic.gyro_still_fit_scale;
  c.pose_min_fit_scale = o.dynamic.pose_min_fit_scale;
  c.pose_smoothness_boost = o.dynamic.pose_smoothness_boost;
  c.centre_variation_low = o.dynamic.centre_variation_low;
  c.centre_variation_high = o.dynamic.centre_variation_high;
  c.scale_variation_low = o.dynamic.scale_variation_low;
  c.scale_variation_high = o.dynamic.scale_variation_high;
  c.variation_min_fit_scale = o.dynamic.variation_min_fit_scale;
  c.gyro_only = o.gyro_only;
  c.min_face_confidence = o.min_face_confidence;
  c.protrusion_search_steps = o.protrusion_search_steps;
  c.solver_max_iterations = o.solver.max_iterations;
  c.smooth_head_in_virtual_view = o.smooth_head_in_virtual_view;
  c.warp_mode = steadiface::WarpModeName(w.mode);
  c.band_width = w.layered.blend.band_width;
  c.band_inside = w.layered.blend.band_inside;
  c.outline_margin = w.layered.blend.outline_margin_cells;
  c.max_offset = w.layered.blend.max_offset;
  c.offset_lowpass = w.layered.blend.offset_lowpass_hz;
  c.yield_to_subject = w.layered.blend.yield_to_subject;
  c.head_width_scale = w.layered.region.head_width_scale;
  c.head_top_scale = w.layered.region.head_top_scale;
  c.torso = w.layered.region.torso;
  c.shoulder_width_scale = w.layered.region.shoulder_width_scale;
  return c;
}

}  // namespace steadiface_ros

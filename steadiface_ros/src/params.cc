#include "steadiface_ros/params.h"

#include <cmath>
#include <map>
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

// The table of every key (config/parameters.yaml, generated).
const std::vector<ParameterSpec>& Table() {
  static const std::vector<ParameterSpec> table = {
#include "parameter_table.inc"
  };
  return table;
}

const ParameterSpec* Find(const std::string& key) {
  static const std::map<std::string, const ParameterSpec*> by_key = [] {
    std::map<std::string, const ParameterSpec*> m;
    for (const ParameterSpec& p : Table()) m[p.key] = &p;
    return m;
  }();
  const auto it = by_key.find(key);
  return it == by_key.end() ? nullptr : it->second;
}

// Reads `key` if present, checked against its row of the table (range or
// choices). Records the first error.
class Reader {
 public:
  explicit Reader(const ParamSource& p) : p_(p) {}
  void Num(const std::string& key, double* v) {
    const ParameterSpec* spec = Spec(key, ParameterType::kDouble);
    double x = *v;
    if (!p_.Get(key, &x)) {
      int i;
      if (p_.Get(key, &i)) x = i;
    }
    if (spec == nullptr) return;
    if (!std::isfinite(x) || x < spec->min || x > spec->max) {
      Fail(key, x, spec->min, spec->max);
      return;
    }
    *v = x;
  }
  void Int(const std::string& key, int* v) {
    const ParameterSpec* spec = Spec(key, ParameterType::kInt);
    int x = *v;
    p_.Get(key, &x);
    if (spec == nullptr) return;
    if (x < spec->min || x > spec->max) {
      Fail(key, x, spec->min, spec->max);
      return;
    }
    *v = x;
  }
  void Bool(const std::string& key, bool* v) {
    Spec(key, ParameterType::kBool);
    p_.Get(key, v);
  }
  void Str(const std::string& key, std::string* v) {
    Spec(key, ParameterType::kString);
    p_.Get(key, v);
  }
  // One of the key's choices (the table's); *v keeps its value otherwise.
  void Choice(const std::string& key, std::string* v) {
    const ParameterSpec* spec = Spec(key, ParameterType::kString);
    std::string x = *v;
    p_.Get(key, &x);
    if (spec == nullptr) return;
    std::stringstream choices(spec->choices);
    std::string c, all;
    while (std::getline(choices, c, '|')) {
      if (c == x) {
        *v = x;
        return;
      }
      all += (all.empty() ? "" : " | ") + c;
    }
    Error("parameter '" + key + "' must be one of " + all + ", got '" + x + "'");
  }
  // A file parameter: a plain path, file:// or package:// (ResolveResourceUrl).
  void Path(const std::string& key, std::string* v) {
    Spec(key, ParameterType::kString);
    std::string url = *v;
    p_.Get(key, &url);
    if (url.empty()) {
      *v = url;
      return;
    }
    const Status s = ResolveResourceUrl("parameter '" + key + "'", url, v);
    if (!s.ok()) Error(s.message());
  }
  void Vec(const std::string& key, std::vector<double>* v) {
    Spec(key, ParameterType::kList);
    p_.Get(key, v);
  }
  void Error(const std::string& msg) {
    if (error_.empty()) error_ = msg;
  }
  Status status() const { return error_.empty() ? Status::Ok() : Status::Error(error_); }

 private:
  // The key's row; a key the table lacks, or of another type, is an error
  // (a programming one: params_test reads every key).
  const ParameterSpec* Spec(const std::string& key, ParameterType type) {
    const ParameterSpec* spec = Find(key);
    if (spec == nullptr || spec->type != type) {
      Error("parameter '" + key + "' is not in config/parameters.yaml as this type");
      return nullptr;
    }
    return spec;
  }
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

namespace {

// LoadOptions' pieces, one per section of the table.
void ReadRosLayer(Reader& r, steadiface::PipelineOptions* po, WrapperOptions* wo) {
  using steadiface::LandmarkSource;
  using steadiface::LateFramePolicy;
  using steadiface::RotationSource;
  r.Str("camera_frame", &wo->camera_frame);
  r.Choice("image_transport", &wo->image_transport);
  r.Str("camera_info_url", &wo->camera_info_url);
  r.Str("stabilized_suffix", &wo->stabilized_suffix);
  r.Str("world_frame", &wo->world_frame);
  r.Bool("publish_world_tf", &wo->publish_world_tf);
  r.Bool("imu_extrinsics_from_tf", &wo->imu_extrinsics_from_tf);
  steadiface::FrameSchedulerOptions& fs = wo->scheduler;
  r.Num("max_gyro_wait", &fs.max_gyro_wait_s);
  std::string policy = fs.late_frame_policy == LateFramePolicy::kDrop ? "drop" : "extrapolate";
  r.Choice("late_frame_policy", &policy);
  fs.late_frame_policy = policy == "drop" ? LateFramePolicy::kDrop : LateFramePolicy::kExtrapolate;
  r.Int("frame_queue_size", &fs.frame_queue_size);
  r.Num("imu_timeout", &fs.imu_timeout_s);
  r.Num("imu_gap_warn", &fs.imu_gap_warn_s);
  r.Num("expected_image_rate", &wo->expected_image_rate);
  r.Num("expected_imu_rate", &wo->expected_imu_rate);
  r.Bool("passthrough_without_imu", &wo->passthrough_without_imu);
  r.Bool("pipelined", &wo->pipelined);
  r.Num("pipeline_hold", &fs.pipeline_hold_s);
  std::string source = po->landmark_source == LandmarkSource::kExternal ? "topic"
                       : po->landmark_source == LandmarkSource::kNone   ? "none"
                                                                        : "dlib";
  r.Choice("landmark_source", &source);
  std::string rotation = po->rotation_source == RotationSource::kVisual ? "visual"
                         : po->rotation_source == RotationSource::kAuto ? "auto"
                                                                         : "imu";
  r.Choice("rotation_source", &rotation);
  po->rotation_source = rotation == "visual" ? RotationSource::kVisual
                        : rotation == "auto" ? RotationSource::kAuto
                                             : RotationSource::kImu;
  po->landmark_source = source == "topic"  ? LandmarkSource::kExternal
                        : source == "none" ? LandmarkSource::kNone
                                           : LandmarkSource::kDlib;
}

void ReadCamera(Reader& r, steadiface::PipelineOptions* po) {
  using steadiface::StampConvention;
  r.Num("camera/readout_time", &po->shutter.readout_time_s);
  const StampConvention s0 = po->shutter.stamp;
  std::string stamp = s0 == StampConvention::kMiddleRow ? "middle_row"
                      : s0 == StampConvention::kLastRow ? "last_row"
                                                        : "first_row";
  r.Choice("camera/stamp", &stamp);
  po->shutter.stamp = stamp == "middle_row" ? StampConvention::kMiddleRow
                      : stamp == "last_row" ? StampConvention::kLastRow
                                            : StampConvention::kFirstRow;
  r.Num("camera/row_time_offset", &po->shutter.row_time_offset_s);
  r.Num("camera/virtual_focal_scale", &po->camera.virtual_focal_scale);
}

void ReadImu(Reader& r, steadiface::OrientationTimelineOptions* imu) {
  const Eigen::Quaterniond& q0 = imu->R_cam_imu;
  std::vector<double> q = {q0.x(), q0.y(), q0.z(), q0.w()};
  r.Vec("imu/R_cam_imu", &q);
  if (q.size() != 4) {
    r.Error("parameter 'imu/R_cam_imu' must be a quaternion [x, y, z, w]");
  } else {
    const Eigen::Quaterniond e(q[3], q[0], q[1], q[2]);
    if (!(e.norm() > 0.5 && e.norm() < 2.0)) {
      r.Error("parameter 'imu/R_cam_imu' must be a unit quaternion [x, y, z, w]");
    } else {
      imu->R_cam_imu = e.normalized();
    }
  }
  r.Num("imu/time_offset", &imu->imu_time_offset_s);
  const Eigen::Vector3d& b0 = imu->gyro_bias;
  std::vector<double> b = {b0.x(), b0.y(), b0.z()};
  r.Vec("imu/gyro_bias", &b);
  if (b.size() != 3 || !std::isfinite(b[0]) || !std::isfinite(b[1]) || !std::isfinite(b[2]) ||
      Eigen::Vector3d(b[0], b[1], b[2]).norm() >= 1.0) {
    r.Error("parameter 'imu/gyro_bias' must be [bx, by, bz] in rad/s with |bias| < 1");
  } else {
    imu->gyro_bias = Eigen::Vector3d(b[0], b[1], b[2]);
  }
  r.Num("imu/buffer_duration", &imu->buffer_duration_s);
  r.Int("imu/max_samples", &imu->max_samples);
  r.Num("imu/max_angular_rate", &imu->max_angular_rate);
  r.Num("imu/max_gap", &imu->max_gap_s);
  r.Num("imu/max_extrapolation", &imu->max_extrapolation_s);
}

void ReadFace(Reader& r, steadiface::FaceTrackerOptions* f) {
  using steadiface::FaceDetectorType;
  std::string det =
      f->detector.type == FaceDetectorType::kOpenCvCascade ? "opencv_cascade" : "dlib_hog";
  r.Choice("face/detector", &det);
  f->detector.type =
      det == "opencv_cascade" ? FaceDetectorType::kOpenCvCascade : FaceDetectorType::kDlibHog;
  r.Int("face/detector_max_side", &f->detector.max_side_px);
  // Resolved only where it is used: a package:// cascade must not stop a
  // dlib_hog run started outside a sourced workspace.
  if (f->detector.type == FaceDetectorType::kOpenCvCascade) {
    r.Path("face/cascade_path", &f->detector.cascade_path);
  } else {
    r.Str("face/cascade_path", &f->detector.cascade_path);
  }
  r.Num("face/dlib_threshold", &f->detector.dlib_threshold);
  r.Int("face/min_face_px", &f->detector.min_face_px);
  r.Path("face/landmark_model", &f->landmark_model_path);
  r.Int("face/redetect_every", &f->redetect_every_frames);
  r.Num("face/redetect_region_scale", &f->redetect_region_scale);
  r.Int("face/redetect_face_px", &f->redetect_face_px);
  r.Int("face/small_face_fit_px", &f->small_face_fit_px);
  r.Num("face/lost_timeout", &f->lost_timeout_s);
  r.Num("face/search_interval", &f->search_interval_s);
  r.Num("face/max_shape_residual", &f->max_shape_residual);
  r.Num("face/min_spread_ratio", &f->min_spread_ratio);
  r.Num("face/max_spread_ratio", &f->max_spread_ratio);
  r.Num("face/max_jump", &f->max_jump);
  r.Num("face/min_appearance", &f->min_appearance);
  r.Num("face/min_region_appearance", &f->min_region_appearance);
  r.Bool("face/estimate_head_pose", &f->estimate_head_pose);
}

void ReadObjective(Reader& r, steadiface::StabilizerOptions* s) {
  r.Num("head/w_stay", &s->head.w_stay);
  r.Num("head/w_follow", &s->head.w_follow);
  r.Num("head/d_ref", &s->head.d_ref);
  r.Num("weights/fit", &s->weights.fit);
  r.Num("weights/distortion", &s->weights.distortion);
  r.Num("weights/follow", &s->weights.follow);
  r.Num("weights/rotation_c0", &s->weights.rotation_c0);
  r.Num("weights/rotation_c1", &s->weights.rotation_c1);
  r.Num("weights/translation_c0", &s->weights.translation_c0);
  r.Num("weights/translation_c1", &s->weights.translation_c1);
  r.Num("weights/protrusion", &s->weights.protrusion);
  r.Num("terms/distortion_threshold", &s->terms.distortion_threshold_rad);
  r.Num("terms/distortion_slope", &s->terms.distortion_slope);
  r.Num("terms/protrusion_alpha", &s->terms.protrusion_alpha);
  r.Num("terms/protrusion_shrink", &s->terms.protrusion_shrink);
  r.Int("terms/protrusion_samples_per_edge", &s->terms.protrusion_samples_per_edge);
}

void ReadDynamicWeights(Reader& r, steadiface::DynamicWeightOptions* d) {
  r.Bool("dynamic/enabled", &d->enabled);
  r.Num("dynamic/fade_time", &d->fade_time_s);
  r.Num("dynamic/gyro_window", &d->gyro_window_s);
  r.Num("dynamic/gyro_still", &d->gyro_still_rad_s);
  r.Num("dynamic/gyro_active", &d->gyro_active_rad_s);
  r.Num("dynamic/gyro_still_fit_scale", &d->gyro_still_fit_scale);
  r.Num("dynamic/pose_low", &d->pose_low_rad);
  r.Num("dynamic/pose_high", &d->pose_high_rad);
  r.Num("dynamic/pose_min_fit_scale", &d->pose_min_fit_scale);
  r.Num("dynamic/pose_smoothness_boost", &d->pose_smoothness_boost);
  r.Int("dynamic/variation_window", &d->variation_window);
  r.Num("dynamic/centre_variation_low", &d->centre_variation_low);
  r.Num("dynamic/centre_variation_high", &d->centre_variation_high);
  r.Num("dynamic/scale_variation_low", &d->scale_variation_low);
  r.Num("dynamic/scale_variation_high", &d->scale_variation_high);
  r.Num("dynamic/variation_min_fit_scale", &d->variation_min_fit_scale);
}

void ReadSolverAndStabilizer(Reader& r, steadiface::StabilizerOptions* s) {
  r.Int("solver/max_iterations", &s->solver.max_iterations);
  r.Num("solver/function_tolerance", &s->solver.function_tolerance);
  r.Num("solver/max_time", &s->solver.max_time_s);
  r.Int("stabilizer/protrusion_search_steps", &s->protrusion_search_steps);
  r.Int("stabilizer/row_rotation_samples", &s->row_rotation_samples);
  r.Num("stabilizer/min_face_confidence", &s->min_face_confidence);
  r.Bool("stabilizer/gyro_only", &s->gyro_only);
  r.Bool("stabilizer/background_layer", &s->background_layer);
  r.Bool("stabilizer/smooth_head_in_virtual_view", &s->smooth_head_in_virtual_view);
  r.Num("stabilizer/intentional_window", &s->intentional_window_s);
  r.Num("stabilizer/subject_reach", &s->subject_reach);
}

void ReadOutputAndWarp(Reader& r, steadiface::WarpOptions* w) {
  r.Num("output/crop_ratio", &w->output.crop_ratio);
  r.Int("output/width", &w->output.width);
  r.Int("output/height", &w->output.height);
  r.Int("warp/mesh_cols", &w->mesh_cols);
  r.Int("warp/mesh_rows", &w->mesh_rows);
  r.Int("warp/num_threads", &w->num_threads);
  r.Bool("warp/fixed_point_maps", &w->fixed_point_maps);
  std::string mode = steadiface::WarpModeName(w->mode);
  r.Choice("warp/mode", &mode);
  const Status ms = steadiface::ParseWarpMode(mode, &w->mode);
  if (!ms.ok()) r.Error("parameter 'warp/mode': " + ms.message());
}

void ReadCrop(Reader& r, steadiface::DynamicCropOptions* c) {
  std::string mode = steadiface::CropModeName(c->mode);
  r.Choice("output/crop", &mode);
  const Status ms = steadiface::ParseCropMode(mode, &c->mode);
  if (!ms.ok()) r.Error("parameter 'output/crop': " + ms.message());
  r.Num("output/dynamic/widest_crop_ratio", &c->widest_crop_ratio);
  r.Num("output/dynamic/headroom", &c->headroom);
  r.Num("output/dynamic/extra", &c->extra);
  r.Num("output/dynamic/memory", &c->memory_s);
  r.Num("output/dynamic/max_widen_rate", &c->max_widen_rate);
  r.Num("output/dynamic/max_widen_accel", &c->max_widen_accel);
  r.Num("output/dynamic/max_tighten_rate", &c->max_tighten_rate);
  r.Num("output/dynamic/max_tighten_accel", &c->max_tighten_accel);
  r.Num("output/dynamic/shake_path_hz", &c->shake_path_hz);
  r.Bool("output/dynamic/start_wide", &c->start_wide);
}

void ReadHorizon(Reader& r, steadiface::HorizonOptions* h) {
  std::string mode = steadiface::HorizonModeName(h->mode);
  r.Choice("output/horizon", &mode);
  const Status ms = steadiface::ParseHorizonMode(mode, &h->mode);
  if (!ms.ok()) r.Error("parameter 'output/horizon': " + ms.message());
  r.Num("horizon/gravity_tolerance", &h->gravity_tolerance);
  r.Num("horizon/time_constant", &h->time_constant_s);
  r.Num("horizon/lowpass", &h->lowpass_hz);
  r.Num("horizon/warmup", &h->warmup_s);
  r.Num("horizon/level_weight", &h->level_weight);
  r.Num("horizon/lock_weight", &h->lock_weight);
}

void ReadLayered(Reader& r, steadiface::LayeredWarpOptions* lw) {
  r.Int("warp/layered/mesh_cols", &lw->mesh_cols);
  r.Int("warp/layered/mesh_rows", &lw->mesh_rows);
  r.Num("warp/layered/band_width", &lw->blend.band_width);
  r.Num("warp/layered/band_inside", &lw->blend.band_inside);
  r.Num("warp/layered/outline_margin", &lw->blend.outline_margin_cells);
  r.Num("warp/layered/face_core", &lw->blend.face_core_cells);
  r.Num("warp/layered/max_offset", &lw->blend.max_offset);
  r.Num("warp/layered/offset_lowpass", &lw->blend.offset_lowpass_hz);
  r.Num("warp/layered/band_data_weight", &lw->blend.band_data_weight);
  r.Num("warp/layered/shape_weight", &lw->blend.shape_weight);
  r.Num("warp/layered/temporal_weight", &lw->blend.temporal_weight);
  r.Num("warp/layered/min_cell_ratio", &lw->blend.min_cell_ratio);
  r.Bool("warp/layered/yield_to_subject", &lw->blend.yield_to_subject);
  r.Num("warp/layered/head_width_scale", &lw->region.head_width_scale);
  r.Num("warp/layered/head_top_scale", &lw->region.head_top_scale);
  r.Bool("warp/layered/torso", &lw->region.torso);
  r.Num("warp/layered/shoulder_width_scale", &lw->region.shoulder_width_scale);
  r.Num("warp/layered/neck_width_scale", &lw->region.neck_width_scale);
  r.Num("warp/layered/region_smoothing", &lw->region.smoothing_s);
  r.Num("warp/layered/ramp", &lw->region.ramp_s);
}

void ReadComposite(Reader& r, steadiface::CompositeOptions* c) {
  r.Num("composite/plate_below", &c->plate_below);
  r.Int("composite/plate_distance", &c->plate_distance_px);
  r.Int("composite/plate_row_step", &c->plate_row_step);
  r.Int("composite/matte/scale", &c->matte.scale);
  r.Num("composite/matte/search", &c->matte.search_jaw_widths);
  r.Num("composite/matte/prior_softness", &c->matte.prior_softness);
  r.Num("composite/matte/plate_level", &c->matte.plate_level);
  r.Num("composite/matte/motion_level", &c->matte.motion_level);
  r.Num("composite/matte/motion_memory", &c->matte.motion_memory);
  r.Num("composite/matte/plate_confidence", &c->matte.plate_confidence);
  r.Num("composite/matte/colour_weight", &c->matte.colour_weight);
  r.Num("composite/matte/temporal", &c->matte.temporal);
  r.Int("composite/matte/edge_radius", &c->matte.edge_radius_px);
  r.Num("composite/matte/edge_eps", &c->matte.edge_eps);
  r.Num("composite/plate/margin", &c->plate.margin);
  r.Num("composite/plate/max_age", &c->plate.max_age_s);
  r.Num("composite/plate/update_rate", &c->plate.update_rate);
  r.Num("composite/plate/outlier_level", &c->plate.outlier_level);
  r.Num("composite/plate/reset_angle", &c->plate.reset_angle_deg);
  r.Num("composite/plate/scene_cut_level", &c->plate.scene_cut_level);
}

void ReadGyroVideoCheck(Reader& r, steadiface::GyroVideoCheckOptions* c) {
  r.Bool("gyro_video_check/enabled", &c->enabled);
  r.Int("gyro_video_check/stride", &c->stride);
  r.Int("gyro_video_check/track_width", &c->track_width);
  r.Int("gyro_video_check/max_features", &c->max_features);
  r.Num("gyro_video_check/max_fb_error", &c->max_fb_error_px);
  r.Num("gyro_video_check/window", &c->window_s);
  r.Num("gyro_video_check/offset_range", &c->offset_range_s);
  r.Num("gyro_video_check/offset_step", &c->offset_step_s);
  r.Int("gyro_video_check/min_pairs", &c->min_pairs);
  r.Num("gyro_video_check/min_motion", &c->min_motion_px);
  r.Num("gyro_video_check/better_mounting_ratio", &c->better_mounting_ratio);
  r.Num("gyro_video_check/offset_warn", &c->offset_warn_s);
  r.Bool("gyro_video_check/apply_offset", &c->apply_offset);
  r.Num("gyro_video_check/apply_rate", &c->apply_rate_s_per_s);
}

}  // namespace

const std::vector<ParameterSpec>& ParameterTable() { return Table(); }

Status LoadOptions(const ParamSource& params, steadiface::PipelineOptions* po,
                   WrapperOptions* wo) {
  Reader r(params);
  ReadRosLayer(r, po, wo);
  ReadCamera(r, po);
  ReadImu(r, &po->imu);
  ReadFace(r, &po->face);
  ReadObjective(r, &po->stabilizer);
  ReadDynamicWeights(r, &po->stabilizer.dynamic);
  ReadSolverAndStabilizer(r, &po->stabilizer);
  ReadOutputAndWarp(r, &po->warp);
  ReadCrop(r, &po->crop);
  ReadHorizon(r, &po->horizon);
  ReadLayered(r, &po->warp.layered);
  ReadComposite(r, &po->composite);
  ReadGyroVideoCheck(r, &po->gyro_video_check);
  const Status st = r.status();
  if (!st.ok()) return st;
  // Cross-field checks of the core (e.g. low < high) with its own messages.
  return steadiface::ValidatePipelineOptions(*po);
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
  layered->blend.face_core_cells = c.face_core;
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
  c.face_core = w.layered.blend.face_core_cells;
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

#include "steadiface_core/pipeline/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "steadiface_core/common/grey.h"
#include "steadiface_core/common/stopwatch.h"
#include "steadiface_core/view/crop_need.h"
#include "steadiface_core/warp/mesh_sampler.h"

namespace steadiface {
namespace {

// The timeline a stream integrates: the IMU's as configured, or with the
// visual source camera-frame rates on the camera clock.
OrientationTimelineOptions TimelineOptions(const PipelineOptions& o) {
  if (o.rotation_source != RotationSource::kVisual) return o.imu;
  OrientationTimelineOptions v = o.imu;
  v.R_cam_imu = Eigen::Quaterniond::Identity();
  v.gyro_bias = Eigen::Vector3d::Zero();
  v.imu_time_offset_s = 0.0;
  return v;
}

}  // namespace

Status ValidatePipelineOptions(const PipelineOptions& o) {
  Status s = ValidateCameraModelOptions(o.camera);
  if (!s.ok()) return s;
  s = ValidateRollingShutterOptions(o.shutter);
  if (!s.ok()) return s;
  s = ValidateOrientationTimelineOptions(o.imu);
  if (!s.ok()) return s;
  if (o.landmark_source == LandmarkSource::kDlib) {
    s = ValidateFaceTrackerOptions(o.face);
    if (!s.ok()) return s;
  }
  s = ValidateStabilizerOptions(o.stabilizer);
  if (!s.ok()) return s;
  s = ValidateGyroVideoCheckOptions(o.gyro_video_check);
  if (!s.ok()) return s;
  s = ValidateCompositeOptions(o.composite);
  if (!s.ok()) return s;
  if (o.rotation_source != RotationSource::kImu) {
    s = ValidateVisualRotationOptions(o.visual);
    if (!s.ok()) return s;
  }
  s = ValidateWarpOptions(o.warp);
  if (!s.ok()) return s;
  s = ValidateHorizonOptions(o.horizon);
  if (!s.ok()) return s;
  return ValidateDynamicCropOptions(o.crop);
}

std::string OptionsConflict(const PipelineOptions& o) {
  if (o.warp.mode == WarpMode::kComposite && o.crop.mode == CropMode::kDynamic) {
    // On seed 2 of vlog, hair and walk the matte lost most of the subject.
    return "the composite's matte and plate do not follow the dynamic crop's zoom: "
           "use output/crop fixed with warp/mode composite";
  }
  return "";
}

Pipeline::Pipeline(const CameraModel& model, const PipelineOptions& options)
    : model_(model),
      options_(options),
      timing_(options.shutter, model.intrinsics().height),
      timeline_(TimelineOptions(options)),
      region_(new SubjectRegionTracker(options.warp.layered.region)),
      crop_(new DynamicCrop(options.crop, options.warp.output.crop_ratio)),
      shake_path_(options.crop.shake_path_hz),
      gravity_(options.horizon) {}

StabilizerOptions ForWarp(const StabilizerOptions& options, const WarpOptions& warp) {
  StabilizerOptions o = options;
  // The composite needs the background layer's pose every frame; the
  // subject layer is the global warp's (H is not held: the plate fills what
  // the subject uncovers).
  if (warp.mode == WarpMode::kComposite) o.background_layer = true;
  if (warp.mode != WarpMode::kLayered) return o;
  // The layered warp needs the background layer's pose every frame, and
  // holds H within what the band absorbs of where that layer shows the face
  // (unless a reach is given), so the face never moves the background.
  o.background_layer = true;
  if (!(o.subject_reach > 0.0)) {
    o.subject_reach = warp.layered.blend.band_width * warp.layered.blend.max_offset;
  }
  return o;
}

Status Pipeline::Create(const CameraIntrinsics& intrinsics,
                        const PipelineOptions& options,
                        std::unique_ptr<Pipeline>* out) {
  Status s = ValidatePipelineOptions(options);
  if (!s.ok()) return s;
  CameraModel model;
  s = CameraModel::Create(intrinsics, options.camera, &model);
  if (!s.ok()) return s;
  // options_ keeps the stabilizer options as requested; the stabilizer
  // gets them as the warp needs them (ForWarp), derived anew on every change.
  std::unique_ptr<Pipeline> p(new Pipeline(model, options));
  if (options.landmark_source != LandmarkSource::kNone) {
    // External landmarks still go through the tracker's checks and
    // face-of-interest logic (no model file needed for them, but the
    // tracker loads it; a missing file is an error only for kDlib).
    FaceTrackerOptions fo = options.face;
    // A head followed through a turn turns about the pose-invariant
    // centre's pivot (one model for both).
    fo.head_pivot_depth = options.stabilizer.dynamic.pose_pivot_depth;
    s = FaceTracker::Create(model, fo, &p->tracker_);
    if (!s.ok()) return s;
  }
  s = Stabilizer::Create(model, options.warp.output, ForWarp(options.stabilizer, options.warp),
                         &p->stabilizer_);
  if (!s.ok()) return s;
  s = Warper::Create(model, options.warp, &p->warper_);
  if (!s.ok()) return s;
  if (options.warp.mode == WarpMode::kComposite) {
    s = Compositor::Create(p->warper_->output_geometry(), options.composite, &p->compositor_);
    if (!s.ok()) return s;
  }
  if (options.rotation_source != RotationSource::kImu) {
    s = VisualRotationEstimator::Create(model, p->timing_, options.visual, &p->visual_);
    if (!s.ok()) return s;
  }
  if (options.rotation_source != RotationSource::kVisual && options.gyro_video_check.enabled) {
    s = GyroVideoCheck::Create(model.intrinsics(), p->timing_, options.imu.R_cam_imu.normalized(),
                               options.gyro_video_check, &p->check_);
    if (!s.ok()) return s;
  }
  *out = std::move(p);
  return Status::Ok();
}

bool Pipeline::AddAccel(const AccelSample& sample) {
  // kVisual: the world frame is the video's; the horizon is off then.
  if (options_.rotation_source == RotationSource::kVisual) return false;
  const Eigen::Vector3d a_cam = options_.imu.R_cam_imu.normalized() * sample.linear_acceleration;
  return gravity_.Add(sample.stamp + FromSeconds(options_.imu.imu_time_offset_s), a_cam, timeline_);
}

Status Pipeline::ProcessFrame(const cv::Mat& image, Time stamp,
                              const std::vector<Eigen::Vector2d>* external,
                              double external_confidence, PipelineFrame* out) {
  const auto t0 = std::chrono::steady_clock::now();
  const CameraIntrinsics& k = model_.intrinsics();
  if (image.empty() || image.cols != k.width || image.rows != k.height ||
      image.depth() != CV_8U || image.channels() < 1 || image.channels() > 4) {
    return Status::Error("pipeline: image must be 8-bit, 1-4 channels, " +
                         std::to_string(k.width) + "x" + std::to_string(k.height));
  }
  PipelineFrame f;
  cv::Mat grey;
  if (visual_ != nullptr) {
    grey = ToGrey(image);
    f.rotation_from_video = options_.rotation_source == RotationSource::kVisual || imu_missing_;
    Status v = f.rotation_from_video ? VisualStep(grey, stamp, &f)
                                     : visual_->Remember(grey, stamp);
    if (!v.ok()) return v;
    if (options_.rotation_source == RotationSource::kAuto && f.rotation_from_video) {
      video_newest_ = true;
      HandBackToGyro();
    }
    f.withheld = f.rotation_from_video && !has_visual_mid_;
    visual_mid_ = timing_.RowTime(stamp, 0.5 * (k.height - 1));
    has_visual_mid_ = true;
  }
  // Face information.
  const auto t_face = std::chrono::steady_clock::now();
  FaceObservation observation;
  const FaceObservation* obs =
      FaceStep(image, stamp, external, external_confidence, &grey, &observation, &f);
  f.timings.face_ms = MsSince(t_face);
  // The visual source leaves the subject out: the face found, or the lost
  // one where it was last seen, until the tracker searches again.
  if (f.face.located()) {
    last_face_box_ = f.face.box;
  } else if (f.face.state == TrackingState::kSearching) {
    last_face_box_ = cv::Rect2d();
  }
  CheckStep(grey, stamp, &f);
  // Stabilizer, within this frame's crop.
  const auto t_stab = std::chrono::steady_clock::now();
  stabilizer_->SetCropRatio(crop_->crop_ratio());
  warper_->SetCropRatio(crop_->crop_ratio());
  HorizonStep(&f);
  Status s = stabilizer_->Process(stamp, timeline_, timing_, obs, &f.stabilizer);
  f.timings.stabilizer_ms = MsSince(t_stab);
  if (!s.ok()) return s;
  HorizonReportStep(&f);
  CropStep(stamp, &f);
  s = options_.warp.mode == WarpMode::kComposite ? CompositeStep(image, stamp, obs, &f)
                                                : WarpStep(image, stamp, obs, &f);
  if (s.ok() && defer_render_ && options_.warp.mode != WarpMode::kComposite) {
    f.mesh = warper_->mesh();
    f.output_size = cv::Size(warper_->output_geometry().width(),
                             warper_->output_geometry().height());
  }
  f.imu_offset_applied_s = timeline_.offset_correction();
  if (check_ != nullptr && options_.gyro_video_check.apply_offset) ApplyOffsetEstimate(stamp);
  if (!s.ok()) {
    f.output.release();
    *out = std::move(f);
    return s;
  }
  // A withheld frame still sets the stabilizer's and the warp's state (its
  // middle row's rotation is known): only its picture is not shown (global
  // and layered do not draw it; the composite draws it, as its matte and
  // plate learn from it).
  if (f.withheld) f.output.release();
  f.timings.total_ms = MsSince(t0);
  *out = std::move(f);
  return Status::Ok();
}

void Pipeline::CheckStep(const cv::Mat& grey, Time stamp, PipelineFrame* f) {
  // The gyro-vs-video check (never changes the pose), outside the face.
  // It checks the gyro: a frame rotated by the video ends no pair (the
  // video against itself would always agree).
  if (check_ == nullptr) return;
  const auto t_check = std::chrono::steady_clock::now();
  if (f->rotation_from_video) {
    check_->SkipFrame();
  } else {
    check_->Process(grey, stamp, timeline_, f->face.located() ? f->face.box : cv::Rect2d());
  }
  f->gyro_video_check = check_->result();
  f->timings.check_ms = MsSince(t_check);
}

const FaceObservation* Pipeline::FaceStep(const cv::Mat& image, Time stamp,
                                          const std::vector<Eigen::Vector2d>* external,
                                          double external_confidence, cv::Mat* grey_out,
                                          FaceObservation* observation, PipelineFrame* f) {
  const FaceObservation* obs = nullptr;
  // The tracker and the check both work on grey: convert once (the same
  // cv::cvtColor each would run, so their results do not change).
  const bool internal_face =
      tracker_ != nullptr && options_.landmark_source != LandmarkSource::kExternal;
  // (The visual rotation source's grey, when it ran, is the same picture.)
  if (grey_out->empty()) *grey_out = internal_face ? ToGrey(image) : image;
  const cv::Mat& grey = *grey_out;
  if (tracker_ != nullptr) {
    Status s;
    if (options_.landmark_source == LandmarkSource::kExternal) {
      static const std::vector<Eigen::Vector2d> kNone;
      s = tracker_->ProcessExternal(external != nullptr ? *external : kNone,
                                    external_confidence, stamp, &timeline_, &timing_,
                                    &f->face);
    } else {
      s = tracker_->Process(grey, stamp, &timeline_, &timing_, &f->face);
    }
    // A face error never stops stabilization: it is a frame without a face.
    // A followed head (turned past the landmarks) is held in global mode
    // and by the composite's subject layer (global mode's pose; its matte
    // starts from the followed shape and finds the outline from motion,
    // colour and the plate). Not in layered mode: its band is cut from the
    // landmarks' outline, and the last fit's shape moved with the head is
    // not that outline.
    const bool usable =
        f->face.valid || (f->face.followed && options_.warp.mode != WarpMode::kLayered);
    if (usable) {
      *observation = f->face.ToObservation();
      obs = observation;
    }
  }
  return obs;
}

Status Pipeline::WarpStep(const cv::Mat& image, Time stamp, const FaceObservation* obs,
                          PipelineFrame* out) {
  // The output: one pose warp, or the layered mesh from both layers.
  PipelineFrame& f = *out;
  Status s;
  const bool layered = options_.warp.mode == WarpMode::kLayered;
  // A withheld frame sets the warp's state (its mesh) but is not drawn.
  const bool render = options_.render_output && !defer_render_ && !f.withheld;
  f.output_intrinsics = warper_->output_geometry().VirtualIntrinsics(
      layered && f.stabilizer.background.valid ? f.stabilizer.background.t : f.stabilizer.t);
  if (layered) {
    // The subject region from this frame's face, through the subject layer.
    const double dt = has_last_stamp_ ? ToSeconds(stamp) - ToSeconds(last_stamp_) : 0.0;
    f.layered.active = true;
    f.layered.region = region_->Update(model_, warper_->output_geometry(), f.stabilizer.R_v,
                                      f.stabilizer.t, f.stabilizer.rows, obs,
                                      f.stabilizer.factors.presence_target, dt);
    const StabilizerFrame::LayerPose& b = f.stabilizer.background;
    s = warper_->ComputeLayeredMesh(f.stabilizer.R_v, f.stabilizer.t, b.valid ? b.R_v : f.stabilizer.R_v,
                                    b.valid ? b.t : f.stabilizer.t, f.stabilizer.rows,
                                    f.layered.region, dt);
    f.layered.blend = warper_->blend_report();
    // What the band absorbs (the face's size against the mesh) bounds the
    // next frame's head target.
    const SubjectRegion& region = f.layered.region;
    stabilizer_->SetReachLimit(s.ok() && region.valid && f.layered.blend.layered &&
                                       region.jaw_width > 0.0
                                   ? f.layered.blend.reach_px / region.jaw_width
                                   : 0.0);
    f.timings.mesh_ms = warper_->timings().mesh_ms;
    if (s.ok() && render) {
      s = warper_->Render(image, &f.output);
      f.timings.maps_ms = warper_->timings().maps_ms;
      f.timings.remap_ms = warper_->timings().remap_ms;
    }
    has_last_stamp_ = true;
    last_stamp_ = stamp;
  } else if (render) {
    s = warper_->Warp(image, f.stabilizer.R_v, f.stabilizer.t, f.stabilizer.rows,
                      &f.output);
    f.timings.mesh_ms = warper_->timings().mesh_ms;
    f.timings.maps_ms = warper_->timings().maps_ms;
    f.timings.remap_ms = warper_->timings().remap_ms;
  } else if (defer_render_ || options_.render_output) {
    // The mesh without the picture: drawn later (deferred), or never (a
    // withheld frame, whose mesh is still the warp's state).
    s = warper_->ComputeMesh(f.stabilizer.R_v, f.stabilizer.t, f.stabilizer.rows);
    f.timings.mesh_ms = warper_->timings().mesh_ms;
  }
  return s;
}

Status Pipeline::CompositeStep(const cv::Mat& image, Time stamp, const FaceObservation* obs,
                               PipelineFrame* out) {
  PipelineFrame& f = *out;
  const StabilizerFrame::LayerPose& b = f.stabilizer.background;
  const Eigen::Quaterniond R_b = b.valid ? b.R_v : f.stabilizer.R_v;
  const Eigen::Vector2d t_b = b.valid ? b.t : f.stabilizer.t;
  const OutputGeometry& geometry = warper_->output_geometry();
  f.output_intrinsics = geometry.VirtualIntrinsics(t_b);
  // The subject region from this frame's face, in the background layer's
  // view (where the matte is made).
  const double dt = has_last_stamp_ ? ToSeconds(stamp) - ToSeconds(last_stamp_) : 0.0;
  has_last_stamp_ = true;
  last_stamp_ = stamp;
  f.composite.active = true;
  f.composite.region = region_->Update(model_, geometry, R_b, t_b, f.stabilizer.rows, obs,
                                       f.stabilizer.factors.presence_target, dt);
  if (!options_.render_output) return Status::Ok();
  // Both layers' pictures, then their composite (into the background's).
  Status s = warper_->Warp(image, f.stabilizer.R_v, f.stabilizer.t, f.stabilizer.rows,
                           &subject_picture_);
  double mesh_ms = warper_->timings().mesh_ms, remap_ms = warper_->timings().remap_ms;
  double maps_ms = warper_->timings().maps_ms;
  if (s.ok()) s = warper_->Warp(image, R_b, t_b, f.stabilizer.rows, &f.output);
  f.timings.mesh_ms = mesh_ms + warper_->timings().mesh_ms;
  f.timings.maps_ms = maps_ms + warper_->timings().maps_ms;
  f.timings.remap_ms = remap_ms + warper_->timings().remap_ms;
  if (!s.ok()) return s;
  s = compositor_->Compose(subject_picture_, OutputView(geometry, f.stabilizer.R_v, f.stabilizer.t),
                           f.output, OutputView(geometry, R_b, t_b), f.composite.region,
                           ToSeconds(stamp), &f.output);
  f.composite.report = compositor_->report();
  f.timings.composite_ms = f.composite.report.matte_ms + f.composite.report.plate_ms +
                           f.composite.report.blend_ms;
  return s;
}

Status Pipeline::ProcessFrameDeferred(const cv::Mat& image, Time stamp,
                                      const std::vector<Eigen::Vector2d>* external,
                                      double external_confidence, PipelineFrame* out) {
  defer_render_ = true;
  const Status s = ProcessFrame(image, stamp, external, external_confidence, out);
  defer_render_ = false;
  return s;
}

void Pipeline::RenderDeferred(const cv::Mat& image, PipelineFrame* frame) {
  if (frame->mesh.source.empty() || frame->output_size.area() <= 0) return;
  const auto t0 = std::chrono::steady_clock::now();
  SampleMesh(frame->mesh, image, frame->output_size.width, frame->output_size.height,
             &frame->output);
  frame->timings.maps_ms = 0.0;
  frame->timings.remap_ms = MsSince(t0);
  // The frame's work: processing plus this render (which ran beside the
  // next frame's processing, so this is not the frame's latency).
  frame->timings.total_ms += frame->timings.remap_ms;
}

void Pipeline::HorizonStep(PipelineFrame* f) {
  const HorizonOptions& o = options_.horizon;
  PipelineFrame::Horizon& h = f->horizon;
  h.mode = o.mode;
  HorizonTarget target;
  if (o.mode != HorizonMode::kOff) {
    if (f->rotation_from_video) {
      h.inactive_reason = "visual rotation";
    } else if (!gravity_.valid()) {
      h.inactive_reason = "no accelerometer";
    } else {
      target.active = true;
      target.up_world = gravity_.up_world();
      const bool lock = o.mode == HorizonMode::kLock;
      target.weight = lock ? o.lock_weight : o.level_weight;
      target.tolerance_rad = lock ? 0.0 : o.level_tolerance_deg * M_PI / 180.0;
      target.level_reference = lock;
    }
  }
  h.active = target.active;
  stabilizer_->SetHorizon(target);
}

void Pipeline::HorizonReportStep(PipelineFrame* f) const {
  if (!gravity_.valid() || f->rotation_from_video) return;
  const StabilizerFrame& sf = f->stabilizer;
  const bool background = sf.background.valid && options_.warp.mode != WarpMode::kGlobal;
  const Eigen::Quaterniond& R_out = background ? sf.background.R_v : sf.R_v;
  f->horizon.output_roll_rad = HorizonRoll(R_out * gravity_.up_world());
  f->horizon.real_roll_rad = HorizonRoll(sf.R_r * gravity_.up_world());
}

void Pipeline::CropStep(Time stamp, PipelineFrame* f) {
  const auto t0 = std::chrono::steady_clock::now();
  double shake = 0.0, solved = 0.0;
  if (options_.crop.mode == CropMode::kDynamic) {
    // Room for the shake (the real camera against its low-passed path), and
    // for what the solves asked for before the protrusion search held them
    // in: the subject layer's (in global mode, the face held against the
    // scene) and the background layer's where it has one.
    const StabilizerFrame& sf = f->stabilizer;
    const OutputGeometry& g = warper_->output_geometry();
    const double dt = has_crop_stamp_ ? ToSeconds(stamp - crop_stamp_) : 0.0;
    has_crop_stamp_ = true;
    crop_stamp_ = stamp;
    shake = CropNeed(model_, g, shake_path_.Update(sf.R_r, dt), Eigen::Vector2d::Zero(), sf.rows);
    solved = CropNeed(model_, g, sf.R_v_solved, sf.t_solved, sf.rows);
    if (sf.background.valid) {
      solved = std::max(solved, CropNeed(model_, g, sf.background.R_v_solved,
                                         sf.background.t_solved, sf.rows));
    }
  }
  f->crop = crop_->Update(ToSeconds(stamp), shake, solved);
  f->timings.crop_ms = MsSince(t0);
}

Status Pipeline::Passthrough(const cv::Mat& image, PipelineFrame* out) {
  PipelineFrame f;
  const Eigen::Quaterniond I = Eigen::Quaterniond::Identity();
  f.stabilizer.rows = RowRotations(I, model_.intrinsics().height);
  warper_->SetCropRatio(crop_->crop_ratio());
  f.crop.crop_ratio = f.crop.target = crop_->crop_ratio();
  f.crop.dynamic = options_.crop.mode == CropMode::kDynamic;
  f.output_intrinsics = warper_->output_geometry().VirtualIntrinsics(Eigen::Vector2d::Zero());
  Status s = warper_->Warp(image, I, Eigen::Vector2d::Zero(), f.stabilizer.rows, &f.output);
  f.timings.mesh_ms = warper_->timings().mesh_ms;
  f.timings.maps_ms = warper_->timings().maps_ms;
  f.timings.remap_ms = warper_->timings().remap_ms;
  *out = std::move(f);
  return s;
}

void Pipeline::SetTrueHeadCentre(const Eigen::Vector2d& pixel) {
  // As the tracker's landmarks are: undistorted, then normalized.
  Eigen::Vector2d normalized;
  if (model_.RawPixelToNormalized(pixel, &normalized)) {
    stabilizer_->SetTrueHeadCentre(normalized);
  }
}

Status Pipeline::UpdateStabilizerOptions(const StabilizerOptions& options) {
  Status s = stabilizer_->UpdateOptions(ForWarp(options, options_.warp));
  if (s.ok()) options_.stabilizer = options;
  return s;
}

Status Pipeline::UpdateLayering(WarpMode mode, const LayeredWarpOptions& layered) {
  WarpOptions w = options_.warp;
  w.mode = mode;
  w.layered = layered;
  std::unique_ptr<Warper> warper;
  Status s = Warper::Create(model_, w, &warper);
  if (!s.ok()) return s;
  // The stabilizer's layered options follow the new warp (the reach from the
  // new band width and cap).
  const StabilizerOptions now = ForWarp(options_.stabilizer, options_.warp);
  const StabilizerOptions next = ForWarp(options_.stabilizer, w);
  if (next.background_layer != now.background_layer || next.subject_reach != now.subject_reach) {
    s = stabilizer_->UpdateOptions(next);
    if (!s.ok()) return s;
  }
  std::unique_ptr<Compositor> compositor;
  if (mode == WarpMode::kComposite) {
    s = Compositor::Create(warper->output_geometry(), options_.composite, &compositor);
    if (!s.ok()) return s;
  }
  warper_ = std::move(warper);
  warper_->SetCropRatio(crop_->crop_ratio());
  compositor_ = std::move(compositor);
  if (compositor_ != nullptr) compositor_->KeepPlateUse(keep_plate_use_);
  options_.warp = w;
  region_.reset(new SubjectRegionTracker(layered.region));
  has_last_stamp_ = false;
  return Status::Ok();
}

void Pipeline::Reset() {
  timeline_.Reset();
  video_newest_ = false;
  pending_gyro_.clear();
  if (visual_ != nullptr) visual_->Reset();
  has_visual_mid_ = false;
  if (tracker_ != nullptr) tracker_->Reset();
  stabilizer_->Reset();
  if (check_ != nullptr) check_->Reset();
  region_->Reset();
  warper_->Reset();
  if (compositor_ != nullptr) compositor_->Reset();
  has_last_stamp_ = false;
  // A new epoch starts from the configuration: a replayed bag (rosbag play
  // --loop) reproduces a fresh start exactly; the check finds the offset
  // again within seconds.
  timeline_.set_offset_correction(0.0);
  has_check_stamp_ = false;
  crop_.reset(new DynamicCrop(options_.crop, options_.warp.output.crop_ratio));
  shake_path_.Reset();
  has_crop_stamp_ = false;
  gravity_.Reset();
}

}  // namespace steadiface

#include "steadiface_core/eval/run_methods.h"

#include <algorithm>

namespace steadiface {
namespace eval {

const char* MethodName(Method m) {
  switch (m) {
    case Method::kNone:
      return "none";
    case Method::kGyroOnly:
      return "gyro-only";
    case Method::kSteadiface:
      return "steadiface";
    case Method::kSteadifaceLayered:
      return "steadiface-layered";
    case Method::kSteadifaceComposite:
      return "steadiface-composite";
  }
  return "?";
}

PipelineOptions OptionsFor(const sim::Simulator& sim, Method method) {
  PipelineOptions o;
  o.shutter.readout_time_s = sim.options().readout_s;
  o.shutter.stamp = StampConvention::kFirstRow;
  o.imu.imu_time_offset_s = sim.options().imu_clock_offset_s;
  const bool face = method == Method::kSteadiface || method == Method::kSteadifaceLayered ||
                    method == Method::kSteadifaceComposite;
  o.landmark_source = face ? LandmarkSource::kDlib : LandmarkSource::kNone;
  o.stabilizer.gyro_only = !face;
  if (method == Method::kSteadifaceLayered) o.warp.mode = WarpMode::kLayered;
  if (method == Method::kSteadifaceComposite) o.warp.mode = WarpMode::kComposite;
  o.render_output = false;
  // On a loaded machine (a CI job beside the evaluation) the 20 ms cap cut
  // shake's long solves short: head 49.37 -> 51.55 px in one such run.
  o.stabilizer.solver.max_time_s = 10.0;
  return o;
}

Status MakeScorecard(const sim::Simulator& sim, const PipelineOptions& options,
                     std::unique_ptr<Scorecard>* card, const Eigen::Vector2d& window_s) {
  CameraModel model;
  Status s = CameraModel::Create(sim.intrinsics(), options.camera, &model);
  if (!s.ok()) return s;
  OutputGeometry output;
  s = OutputGeometry::Create(model, options.warp.output, &output);
  if (!s.ok()) return s;
  ScorecardOptions so;
  if (window_s.allFinite()) {
    so.window_start_s = window_s.x();
    so.window_end_s = window_s.y();
  } else if (ImuHasGap(sim.options())) {
    so.window_start_s = sim.options().imu_dropout_start_s;
    so.window_end_s = sim.options().imu_dropout_end_s;
  }
  card->reset(new Scorecard(sim, model, output, so));
  return Status::Ok();
}

FrameWarp MakeFrameWarp(const PipelineFrame& out, const Pipeline& p, bool rendered) {
  FrameWarp w;
  w.kind = FrameWarp::Kind::kPose;
  w.R_v = out.stabilizer.R_v;
  w.t = out.stabilizer.t;
  w.rows = out.stabilizer.rows;
  w.has_head_target = out.stabilizer.has_target;
  w.crop_ratio = out.crop.crop_ratio;
  w.crop_need = std::max(out.crop.shake_need, out.crop.solved_need);
  w.head_target = out.stabilizer.H;
  const bool layered = p.options().warp.mode == WarpMode::kLayered;
  if (layered || p.options().warp.mode == WarpMode::kComposite) {
    // The scene's layer (for the horizon's roll; kComposite's far scene).
    const StabilizerFrame::LayerPose& b = out.stabilizer.background;
    w.R_b = b.valid ? b.R_v : out.stabilizer.R_v;
    w.t_b = b.valid ? b.t : out.stabilizer.t;
  }
  if (p.options().warp.mode == WarpMode::kComposite) {
    const StabilizerFrame::LayerPose& b = out.stabilizer.background;
    w.kind = FrameWarp::Kind::kComposite;
    w.R_b = b.valid ? b.R_v : out.stabilizer.R_v;
    w.t_b = b.valid ? b.t : out.stabilizer.t;
  }
  if (layered) {
    // The joined mesh is the warp (the subject pose holds only inside the
    // region).
    const WarpMesh& m = p.warper().mesh();
    w.kind = FrameWarp::Kind::kMesh;
    w.mesh_u = m.u;
    w.mesh_v = m.v;
    w.mesh_source = m.source;
    w.mesh_background = p.warper().background_mesh();
    if (p.warper().layer_blend() != nullptr) {
      w.mesh_blend = p.warper().layer_blend()->vertex_blend();
    }
  }
  w.stage_ms = {{"face", out.timings.face_ms},
                {"stabilizer", out.timings.stabilizer_ms},
                {"solver", out.stabilizer.solver.time_ms}};
  if (layered) w.stage_ms.push_back({"mesh", out.timings.mesh_ms});
  if (rendered) {
    w.stage_ms.push_back({"warp", out.timings.mesh_ms + out.timings.maps_ms + out.timings.remap_ms});
  }
  return w;
}

void FeedGyroForFrame(const sim::Simulator& sim, Time stamp, double imu_time_offset_s,
                      Pipeline* pipeline, size_t* next) {
  const auto& imu = sim.imu();
  const auto& accel = sim.accel();
  const Time need = pipeline->LastRowTime(stamp);
  // A live node waits for the gyro a little past the frame, not for ever:
  // across an IMU dropout the frame comes first.
  const Time latest = need + FromSeconds(kGyroWaitS);
  while (*next < imu.size() && imu[*next].stamp + FromSeconds(imu_time_offset_s) <= latest &&
         (!pipeline->GyroCovers(stamp) ||
          imu[*next].stamp + FromSeconds(imu_time_offset_s) <= need)) {
    pipeline->AddGyro(imu[*next]);
    if (*next < accel.size()) pipeline->AddAccel(accel[*next]);  // one IMU message
    ++*next;
  }
}

Status RunMethod(const sim::Simulator& sim, Method method, const PipelineOptions& options,
                 Scorecard* card, const RunMethodOptions& run) {
  const bool render = run.render;
  const auto& on_output = run.on_output;
  if (method == Method::kNone) {
    cv::Mat frame;
    sim::SimTruth truth;
    for (int i = 0; i < sim.num_frames(); ++i) {
      card->Add(i, FrameWarp());
      if (render && on_output) {
        Status s = sim.Render(i, &frame, &truth);
        if (s.ok()) s = on_output(frame);
        if (!s.ok()) return s;
      }
    }
    return Status::Ok();
  }
  PipelineOptions o = options;
  const bool composite = o.warp.mode == WarpMode::kComposite;
  o.render_output = render || composite;
  std::unique_ptr<Pipeline> p;
  Status s = Pipeline::Create(sim.intrinsics(), o, &p);
  if (!s.ok()) return s;
  std::unique_ptr<CompositeQuality> quality;
  if (composite && run.composite_quality != nullptr) {
    s = CompositeQuality::Create(sim, *p, &quality);
    if (!s.ok()) return s;
    p->KeepCompositePlateUse(true);
    if (!run.composite_frames.empty()) quality->DumpFrames(run.composite_frames, 15);
  }
  size_t g = 0;
  cv::Mat frame;
  sim::SimTruth truth;
  for (int i = 0; i < sim.num_frames(); ++i) {
    const Time stamp = sim.Truth(i).stamp;
    FeedGyroForFrame(sim, stamp, o.imu.imu_time_offset_s, p.get(), &g);
    // As the node does: in auto, a frame the gyro does not cover takes its
    // rotation from the video.
    if (o.rotation_source == RotationSource::kAuto) p->SetImuMissing(!p->GyroCovers(stamp));
    if (o.landmark_source == LandmarkSource::kDlib || o.render_output ||
        o.rotation_source == RotationSource::kVisual ||
        (o.rotation_source == RotationSource::kAuto && ImuHasGap(sim.options()))) {
      s = sim.Render(i, &frame, &truth);
      if (!s.ok()) return s;
    } else {
      frame = cv::Mat(sim.intrinsics().height, sim.intrinsics().width, CV_8UC1,
                      cv::Scalar(0));
    }
    if (run.true_head) {
      const sim::SimTruth t = sim.Truth(i);
      if (t.head_in_view) p->SetTrueHeadCentre(t.head_px);
    }
    PipelineFrame out;
    s = p->ProcessFrame(frame, stamp, nullptr, 0.0, &out);
    if (!s.ok()) return Status::Error("frame " + std::to_string(i) + ": " + s.message());
    if (out.withheld) continue;  // not published: not scored, not rendered
    card->Add(i, MakeFrameWarp(out, *p, render));
    if (quality != nullptr) {
      s = quality->Add(i, *p, out, frame);
      if (!s.ok()) return s;
    }
    if (render && on_output) {
      s = on_output(out.output);
      if (!s.ok()) return s;
    }
    if (run.frames != nullptr) run.frames->push_back(out.stabilizer);
  }
  if (quality != nullptr) *run.composite_quality = quality->Compute();
  return Status::Ok();
}

}  // namespace eval
}  // namespace steadiface

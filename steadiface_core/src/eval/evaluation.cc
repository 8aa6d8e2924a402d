#include "steadiface_core/eval/evaluation.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <set>

#include <opencv2/imgproc.hpp>

#include "eval/evaluation_files.h"
#include "steadiface_core/eval/ffmpeg_baseline.h"
#include "steadiface_core/eval/peer_alignment.h"
#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/eval/video_scorer.h"
#include "steadiface_core/pipeline/pipeline.h"

namespace steadiface {
namespace eval {
namespace {

using OutputSink = std::function<Status(const cv::Mat&)>;

bool KnownMethod(const std::string& name) {
  static const char* const kNames[] = {
      "none",           "gyro-only",       "steadiface",           "steadiface-layered",
      "steadiface-layered/video", "none/video", "steadiface-composite",
      "steadiface-composite/video", "steadiface/video", "gyro-only/video", "ffmpeg-vidstab",
      "ffmpeg-deshake", "ffmpeg-vidstab/aligned", "ffmpeg-deshake/aligned"};
  return std::find(std::begin(kNames), std::end(kNames), name) != std::end(kNames);
}

bool IsPeer(const std::string& name) { return name.compare(0, 7, "ffmpeg-") == 0; }

// `name` is a method with `suffix` after its base name.
bool HasSuffix(const std::string& name, const std::string& suffix) {
  return name.size() > suffix.size() &&
         name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A peer scored through its frames aligned to the input (AlignPeerFrame).
bool IsAligned(const std::string& name) { return HasSuffix(name, "/aligned"); }

bool IsVideo(const std::string& name) { return HasSuffix(name, "/video"); }

// `bgr` as 8-bit grey (a grey picture as it is).
void Grey(const cv::Mat& bgr, cv::Mat* grey) {
  if (bgr.channels() == 1) {
    *grey = bgr;
  } else {
    cv::cvtColor(bgr, *grey, cv::COLOR_BGR2GRAY);
  }
}


// The methods to run (the default set when none is asked for), each known
// and, for ffmpeg's, with ffmpeg there; 0 or the exit status 2.
int ResolveMethods(std::vector<std::string> asked, bool have_ffmpeg, std::ostream& err,
                   std::vector<std::string>* methods) {
  if (asked.empty()) {
    asked = {"none", "gyro-only", "steadiface"};
    if (have_ffmpeg) {
      // The peers, and the approximate scoring path applied to the input and
      // to steadiface's output, so its error can be read off the table.
      asked.insert(asked.end(),
                   {"none/video", "steadiface/video", "ffmpeg-vidstab", "ffmpeg-deshake"});
    } else {
      err << "ffmpeg with vidstab/deshake not found: peer baselines skipped\n";
    }
  }
  for (const std::string& name : asked) {
    if (!KnownMethod(name)) {
      err << "unknown method " << name << "\n";
      return 2;
    }
    if (IsPeer(name) && !have_ffmpeg) {
      err << "method " << name << " needs ffmpeg with the vidstab and deshake filters\n";
      return 2;
    }
  }
  *methods = asked;
  return 0;
}

// The preset's simulator: 3 s (or the recorded trace's whole length) unless
// a duration is given.
Status MakeSimulator(const EvaluationOptions& o, const std::string& preset,
                     sim::SimulatorOptions* so, std::unique_ptr<sim::Simulator>* sim) {
  so->data_dir = o.data_dir;
  so->duration_s = std::isfinite(o.duration_s) ? o.duration_s : 3.0;
  so->width = o.width;
  so->height = o.height;
  so->seed = o.seed;
  Status s = sim::ApplyPreset(preset, so);
  if (std::isfinite(o.gyro_scale)) so->real_gyro_scale = o.gyro_scale;
  if (std::isfinite(o.gyro_speed)) so->real_gyro_speed = o.gyro_speed;
  if (std::isfinite(o.head_distance_m)) so->head.distance_m = o.head_distance_m;
  if (s.ok()) s = SetHeadTurn(o.head_yaw_rad, o.head_turn_speed, &so->head);
  if (s.ok()) s = ScaleHeadMotion(o.head_motion_scale, o.head_jitter_scale, &so->head);
  if (!o.head_model.empty()) {
    so->head_model = o.head_model == "flat" ? "flat" : "relief";
    so->relief.mean_face = o.head_model == "mean-face";
    // A head about as broad as its face (a 15 cm face, a 16.5 cm head).
    if (so->relief.mean_face) {
      so->relief.breadth_face_widths = EvaluationOptions::kMeanFaceHeadBreadth;
    }
  }
  if (std::isfinite(o.head_breadth)) so->relief.breadth_face_widths = o.head_breadth;
  if (s.ok()) s = sim::Simulator::Create(*so, sim);
  if (s.ok() && !std::isfinite(o.duration_s) && (*sim)->real_gyro_span_s() > so->duration_s) {
    // The whole recorded trace once (a 3 s slice of it is a poor sample).
    so->duration_s = std::floor(10.0 * (*sim)->real_gyro_span_s()) / 10.0;
    s = sim::Simulator::Create(*so, sim);
  }
  return s;
}

Method MethodFromName(const std::string& base) {
  return base == "none"                   ? Method::kNone
         : base == "gyro-only"            ? Method::kGyroOnly
         : base == "steadiface-layered"   ? Method::kSteadifaceLayered
         : base == "steadiface-composite" ? Method::kSteadifaceComposite
                                          : Method::kSteadiface;
}

// One method's pipeline options: its defaults for the simulator, then the
// evaluation's overrides.
Status PipelineOptionsFor(const EvaluationOptions& o, const sim::Simulator& sim, Method m,
                          PipelineOptions* out) {
  PipelineOptions& po = *out;
  po = OptionsFor(sim, m);
  if (std::isfinite(o.crop)) po.warp.output.crop_ratio = o.crop;
  const Status view = ApplyViewOverrides(o.view, &po);
  if (!view.ok()) return view;
  if (std::isfinite(o.search_interval_s)) po.face.search_interval_s = o.search_interval_s;
  po.rotation_source = o.rotation_source;
  if (std::isfinite(o.head_w_stay)) po.stabilizer.head.w_stay = o.head_w_stay;
  if (std::isfinite(o.head_d_ref)) po.stabilizer.head.d_ref = o.head_d_ref;
  if (std::isfinite(o.intentional_window_s)) {
    po.stabilizer.intentional_window_s = o.intentional_window_s;
  }
  if (std::isfinite(o.protrusion_alpha_face)) {
    po.stabilizer.terms.protrusion_alpha_face = o.protrusion_alpha_face;
  }
  if (std::isfinite(o.pose_pivot_depth)) {
    po.stabilizer.dynamic.pose_pivot_depth = o.pose_pivot_depth;
  }
  po.stabilizer.subject_reach = o.subject_reach;
  if (std::isfinite(o.reach_lowpass_hz)) {
    po.stabilizer.subject_reach_lowpass_hz = o.reach_lowpass_hz;
  }
  if (std::isfinite(o.reach_hold)) po.stabilizer.subject_reach_hold = o.reach_hold;
  po.warp.layered.blend = o.blend;
  po.composite = o.composite;
  po.imu.imu_time_offset_s += o.offset_error_s;
  po.shutter.readout_time_s = std::max(0.0, po.shutter.readout_time_s + o.readout_error_s);
  return Status::Ok();
}

// One preset: its simulator, the lossless input the ffmpeg peers read (made
// once, removed at the end), and what its runs produce.
class PresetRun {
 public:
  PresetRun(const EvaluationOptions& o, std::string preset) : o_(o), preset_(std::move(preset)) {}
  ~PresetRun() {
    if (!input_dir_.empty()) {
      std::remove((input_dir_ + "/input.mkv").c_str());
      rmdir(input_dir_.c_str());
    }
  }
  Status Start() { return MakeSimulator(o_, preset_, &so_, &sim_); }
  double duration_s() const { return so_.duration_s; }

  // Runs and scores one method; `fatal` marks errors that end the whole run.
  Status Run(const std::string& name, Score* sc, RunFigures* run, bool* fatal,
             std::vector<std::pair<std::string, std::string>>* composite_rows);

 private:
  Status MakeInputVideo();
  Status RunPeer(const std::string& name, VideoScorer* vs, Score* sc, RunFigures* run);
  Status ScoreAligned(const std::string& name, const std::vector<cv::Mat>& frames, Score* sc,
                      RunFigures* run);
  Status RunPipeline(const std::string& name, Method m, bool video, VideoScorer* vs, Score* sc,
                     RunFigures* run,
                     std::vector<std::pair<std::string, std::string>>* composite_rows);
  Status WriteExtras(const std::string& name, Method m, const PipelineOptions& po,
                     const Scorecard& card, const std::vector<StabilizerFrame>& frames);
  std::string OutPath(const std::string& kind, const std::string& name) const {
    return o_.out_dir + "/" + kind + preset_ + "_" + name + ".csv";
  }

  const EvaluationOptions& o_;
  const std::string preset_;
  sim::SimulatorOptions so_;
  std::unique_ptr<sim::Simulator> sim_;
  std::string input_dir_, input_video_;
  // The input's frames in grey, kept as they are rendered for the video,
  // for the aligned peers.
  std::vector<cv::Mat> input_grey_;
};

Status PresetRun::MakeInputVideo() {
  char tmpl[] = "/tmp/steadiface_eval_XXXXXX";
  if (mkdtemp(tmpl) == nullptr) return Status::Error("cannot create a temporary directory");
  input_dir_ = tmpl;
  const std::string path = input_dir_ + "/input.mkv";
  LosslessVideoWriter w;
  Status s = w.Open(path, sim_->intrinsics().width, sim_->intrinsics().height, so_.fps);
  cv::Mat frame;
  sim::SimTruth truth;
  for (int i = 0; s.ok() && i < sim_->num_frames(); ++i) {
    s = sim_->Render(i, &frame, &truth);
    if (s.ok()) s = w.Write(frame);
    if (s.ok()) {
      input_grey_.emplace_back();
      Grey(frame, &input_grey_.back());
    }
  }
  const Status c = w.Close();
  if (s.ok()) s = c;
  if (!s.ok()) return Status::Error("lossless input: " + s.message());
  input_video_ = path;
  return Status::Ok();
}

Status PresetRun::RunPeer(const std::string& name, VideoScorer* vs, Score* sc,
                          RunFigures* run) {
  if (input_video_.empty()) {
    const Status s = MakeInputVideo();
    if (!s.ok()) return s;
  }
  const FfmpegMethod fm = name.compare(0, 14, "ffmpeg-vidstab") == 0 ? FfmpegMethod::kVidstab
                                                                    : FfmpegMethod::kDeshake;
  // Time ffmpeg alone: collect its frames first, score afterwards.
  std::vector<cv::Mat> frames;
  double seconds = 0.0;
  Status s = RunFfmpegStabilizer(
      fm, input_video_, sim_->intrinsics().width, sim_->intrinsics().height, input_dir_,
      [&frames](const cv::Mat& f) {
        frames.push_back(f.clone());
        return Status::Ok();
      },
      &seconds, o_.peer);
  if (s.ok()) run->peer_ms = 1000.0 * seconds / std::max<size_t>(1, frames.size());
  if (s.ok() && IsAligned(name)) return ScoreAligned(name, frames, sc, run);
  for (size_t i = 0; s.ok() && i < frames.size(); ++i) s = vs->Add(frames[i]);
  return s;
}

// The peer's frames scored by the exact scorecard: each aligned to the
// input frame it was made from, the truth mapped through that alignment.
Status PresetRun::ScoreAligned(const std::string& name, const std::vector<cv::Mat>& frames,
                               Score* sc, RunFigures* run) {
  if (frames.size() != input_grey_.size()) {
    return Status::Error(name + ": " + std::to_string(frames.size()) + " frames out of " +
                         std::to_string(input_grey_.size()));
  }
  PipelineOptions po;
  Status s = PipelineOptionsFor(o_, *sim_, Method::kNone, &po);
  std::unique_ptr<Scorecard> card;
  if (s.ok()) s = MakeScorecard(*sim_, po, &card, o_.window_s);
  if (!s.ok()) return s;
  PeerAlignment a;
  cv::Mat out_grey;
  run->alignment_rms_px = 0.0;
  run->alignment_min_inliers = std::numeric_limits<int>::max();
  for (int i = 0; i < static_cast<int>(frames.size()); ++i) {
    Grey(frames[i], &out_grey);
    // Seeded by the frame before (ORB's on the first frame, or if that fails).
    s = AlignPeerFrame(input_grey_[i], out_grey, a.H, i > 0, PeerAlignmentOptions(), &a);
    if (!s.ok()) return Status::Error(name + ", frame " + std::to_string(i) + ": " + s.message());
    run->alignment_rms_px = std::max(run->alignment_rms_px, a.rms_px);
    run->alignment_min_inliers = std::min(run->alignment_min_inliers, a.inliers);
    FrameWarp w;
    w.kind = FrameWarp::Kind::kHomography;
    w.H = a.H;
    card->Add(i, w);
  }
  *sc = card->Compute();
  run->aligned = true;
  return WriteTrajectory(OutPath("traj_", name.substr(0, name.size() - 8) + "-aligned"),
                         card->samples(), {});
}

Status PresetRun::WriteExtras(const std::string& name, Method m, const PipelineOptions& po,
                              const Scorecard& card,
                              const std::vector<StabilizerFrame>& frames) {
  Status s = WriteTrajectory(OutPath("traj_", name), card.samples(), frames);
  if (s.ok() && o_.reach_tube && m == Method::kSteadifaceLayered) {
    s = WriteReachTube(*sim_, po, frames, OutPath("reach_", name));
  }
  if (s.ok() && o_.feasible_set && !frames.empty()) {
    std::vector<Eigen::Vector2d> heads;  // the true head in the input
    for (const auto& p : card.samples()) heads.push_back(p.head_in);
    s = WriteFeasibleSet(sim_->intrinsics(), po, frames, OutPath("feasible_", name), heads,
                         o_.feasible_roll);
  }
  return s;
}

// The share of frames whose face entered E_f (found, passed every check,
// used); NaN without a face-following method.
double FaceFraction(Method m, const std::vector<StabilizerFrame>& frames) {
  if (m == Method::kNone || m == Method::kGyroOnly || frames.empty()) return NAN;
  int used = 0;
  for (const auto& f : frames) used += f.flags.face_used ? 1 : 0;
  return static_cast<double>(used) / frames.size();
}

Status PresetRun::RunPipeline(const std::string& name, Method m, bool video, VideoScorer* vs,
                              Score* sc, RunFigures* run,
                              std::vector<std::pair<std::string, std::string>>* composite_rows) {
  PipelineOptions po;
  Status s = PipelineOptionsFor(o_, *sim_, m, &po);
  run->options_conflict = OptionsConflict(po);
  std::unique_ptr<Scorecard> card;
  if (s.ok()) s = MakeScorecard(*sim_, po, &card, o_.window_s);
  if (!s.ok()) return s;
  std::unique_ptr<FrameAverager> avg;
  if (o_.average_at >= 0 && !video) {
    avg.reset(new FrameAverager(o_.out_dir + "/" + preset_ + "_" + name, o_.average_at));
  }
  FrameAverager* ap = avg.get();
  const OutputSink sink = video            ? OutputSink([vs](const cv::Mat& f) { return vs->Add(f); })
                          : ap != nullptr ? OutputSink([ap](const cv::Mat& f) { return ap->Add(f); })
                                          : nullptr;
  const bool composite = m == Method::kSteadifaceComposite && !video;
  std::vector<StabilizerFrame> frames;
  CompositeQualityScore cq;
  RunMethodOptions ro;
  ro.render = o_.render || video || ap != nullptr;
  ro.frames = &frames;
  ro.on_output = sink;
  ro.composite_quality = composite ? &cq : nullptr;
  if (o_.composite_frames) ro.composite_frames = o_.out_dir + "/composite_" + preset_;
  ro.true_head = o_.true_head;
  s = RunMethod(*sim_, m, po, card.get(), ro);
  if (!s.ok()) return s;
  if (composite) composite_rows->push_back(CompositeRow(preset_, cq));
  if (video) return Status::Ok();
  *sc = card->Compute();
  run->face_fraction = FaceFraction(m, frames);
  for (const auto& st : sc->stage_ms) {
    if (st.first == "solver") run->solver_ms = st.second.first;
    if (st.first == "face") run->face_ms = st.second.first;
  }
  return WriteExtras(name, m, po, *card, frames);
}

Status PresetRun::Run(const std::string& name, Score* sc, RunFigures* run, bool* fatal,
                      std::vector<std::pair<std::string, std::string>>* composite_rows) {
  const bool video = IsVideo(name);
  const bool peer = IsPeer(name);
  run->duration_s = so_.duration_s;
  std::unique_ptr<VideoScorer> vs;
  if (video || (peer && !IsAligned(name))) {
    VideoScorerOptions vo;
    vo.fps = so_.fps;
    const Status s = VideoScorer::Create(sim_->intrinsics(), vo, &vs);
    if (!s.ok()) {
      *fatal = true;
      return s;
    }
  }
  const Status s = peer ? RunPeer(name, vs.get(), sc, run)
                        : RunPipeline(name, MethodFromName(video ? name.substr(0, name.size() - 6)
                                                                 : name),
                                      video, vs.get(), sc, run, composite_rows);
  if (!s.ok()) return s;
  if (vs) {
    *sc = vs->Compute();
    run->face_fraction = vs->face_fraction();
    run->approximate = true;
  }
  return Status::Ok();
}

}  // namespace

Status SetHeadTurn(double yaw_rad, double speed, sim::HeadMotionOptions* h) {
  if (yaw_rad < 0.0 || yaw_rad > 3.2) return Status::Error("--head-yaw must be in [0, 3.2] rad");
  if (speed <= 0.0 || speed > 20.0) return Status::Error("--head-turn-speed must be in (0, 20]");
  if (std::isfinite(yaw_rad)) h->yaw_amplitude_rad = yaw_rad;
  if (std::isfinite(speed)) h->yaw_hz *= speed;
  return Status::Ok();
}

Status ScaleHeadMotion(double k, double j, sim::HeadMotionOptions* h) {
  if (k < 0.0 || j < 0.0) return Status::Error("--head-motion and --head-jitter must be >= 0");
  if (std::isfinite(k)) {
    for (double* a : {&h->bob_amplitude_m, &h->sway_amplitude_m, &h->yaw_amplitude_rad,
                      &h->pitch_amplitude_rad, &h->lean_amplitude_m, &h->drift_amplitude_m}) {
      *a *= k;
    }
  }
  if (std::isfinite(j)) h->jitter_rms_m *= j;
  return Status::Ok();
}

Status ApplyViewOverrides(const ViewOverrides& v, PipelineOptions* po) {
  auto set = [](double flag, double* field) {
    if (std::isfinite(flag)) *field = flag;
  };
  if (v.crop_mode >= 0) {
    po->crop.mode = v.crop_mode == 1 ? CropMode::kDynamic : CropMode::kFixed;
  }
  if (!v.horizon.empty()) {
    const Status s = ParseHorizonMode(v.horizon, &po->horizon.mode);
    if (!s.ok()) return s;
  }
  if (v.start_tight) po->crop.start_wide = false;
  set(v.widest, &po->crop.widest_crop_ratio);
  set(v.level_weight, &po->horizon.level_weight);
  set(v.lock_weight, &po->horizon.lock_weight);
  set(v.level_tolerance_deg, &po->horizon.level_tolerance_deg);
  set(v.gravity_warmup_s, &po->horizon.warmup_s);
  set(v.gravity_tau_s, &po->horizon.time_constant_s);
  set(v.shake_hz, &po->crop.shake_path_hz);
  set(v.headroom, &po->crop.headroom);
  set(v.widen_rate, &po->crop.max_widen_rate);
  set(v.tighten_rate, &po->crop.max_tighten_rate);
  set(v.zoom_accel, &po->crop.max_widen_accel);
  return Status::Ok();
}

int RunEvaluation(const EvaluationOptions& o, std::ostream& out, std::ostream& err) {
  std::string ffmpeg_version;
  const bool have_ffmpeg = FfmpegAvailable(&ffmpeg_version);
  std::vector<std::string> methods;
  const int bad = ResolveMethods(o.methods, have_ffmpeg, err, &methods);
  if (bad != 0) return bad;
  // vidstabtransform's own ranges (zoom -100..100, where 100 would show
  // nothing; smoothing 0..1000).
  const double zoom = o.peer.vidstab_zoom_percent;
  if (!std::isnan(zoom) && !(zoom > -100.0 && zoom < 100.0)) {
    err << "--vidstab-zoom must be in (-100, 100) percent\n";
    return 2;
  }
  if (o.peer.vidstab_smoothing > 1000) {
    err << "--vidstab-smoothing must be at most 1000 frames\n";
    return 2;
  }
  mkdir(o.out_dir.c_str(), 0755);
  std::ofstream json(o.out_dir + "/report.json");
  json << "{\n  \"duration_s\": " << JsonNumber(o.duration_s) << ",\n  \"size\": [" << o.width
       << ", " << o.height << "],\n  \"seed\": " << o.seed << ",\n  \"ffmpeg\": \""
       << (have_ffmpeg ? ffmpeg_version : "") << "\",\n  \"results\": [\n";
  out << TableHeader();
  bool first = true;
  int failures = 0;
  std::vector<std::pair<std::string, std::string>> composite_rows;  // table, csv
  std::set<std::string> warned;  // methods whose options conflict, said once
  for (const std::string& preset : o.presets.empty() ? sim::PresetNames() : o.presets) {
    PresetRun pr(o, preset);
    const Status started = pr.Start();
    if (!started.ok()) {
      err << "preset " << preset << ": " << started.message() << "\n";
      ++failures;
      continue;
    }
    for (const std::string& name : methods) {
      Score sc;
      RunFigures run;
      bool fatal = false;
      const Status s = pr.Run(name, &sc, &run, &fatal, &composite_rows);
      if (fatal) {
        err << name << ": " << s.message() << "\n";
        return 1;
      }
      if (!s.ok()) {
        err << preset << "/" << name << ": " << s.message() << "\n";
        ++failures;
        continue;
      }
      if (!run.options_conflict.empty() && warned.insert(name).second) {
        err << name << ": warning: " << run.options_conflict << "\n";
      }
      out << TableRow(preset, name, sc, run) << std::endl;
      json << (first ? "" : ",\n") << JsonResult(preset, name, sc, run);
      first = false;
    }
  }
  json << "\n  ]\n}\n";
  if (!composite_rows.empty()) {
    WriteCompositeTable(composite_rows, o.out_dir + "/composite_quality.csv", out);
  }
  return failures == 0 ? 0 : 1;
}

}  // namespace eval
}  // namespace steadiface

// steadiface_evaluate: renders simulator presets, runs the methods and
// scores them against ground truth. Prints a markdown table, writes
// report.json and per-(preset, method) trajectory CSVs for the plots.
//
//   steadiface_evaluate --data test/data --out out/eval
//       [--presets walk,run] [--methods none,gyro-only,steadiface,...]
//       [--duration S] [--size 640x360] [--seed 1] [--render]
// Without --duration every preset runs 3 s, except that a preset replaying
// a recorded gyro trace (run) runs the whole trace once.
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <sys/stat.h>
#include <vector>

#include <unistd.h>

#include <cmath>
#include <functional>
#include <memory>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "steadiface_core/common/command_line.h"
#include "steadiface_core/eval/feasible_offsets.h"
#include "steadiface_core/eval/ffmpeg_baseline.h"
#include "steadiface_core/eval/run_methods.h"
#include "steadiface_core/eval/video_scorer.h"

namespace {

using steadiface::eval::Method;

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

// The camera model and output geometry a pipeline with `po` builds for
// `intrinsics`.
steadiface::Status MakeOutputGeometry(const steadiface::CameraIntrinsics& intrinsics,
                                      const steadiface::PipelineOptions& po,
                                      steadiface::CameraModel* model,
                                      steadiface::OutputGeometry* output) {
  const steadiface::Status s = steadiface::CameraModel::Create(intrinsics, po.camera, model);
  return s.ok() ? steadiface::OutputGeometry::Create(*model, po.warp.output, output) : s;
}

// Per frame of a layered run: the time, the true head centre through the
// background layer's pose (where the background layer shows it) and
// whether it is in view [output px], and the radius of the disc the
// stabilizer held H within around where it saw the face there (0: none)
// [output px]: the tube any head that leaves the background alone must stay
// in, for scripts/analysis/reach_bound.py.
steadiface::Status WriteReachTube(const steadiface::sim::Simulator& sim,
                                  const steadiface::PipelineOptions& po,
                                  const std::vector<steadiface::StabilizerFrame>& frames,
                                  const std::string& path) {
  std::unique_ptr<steadiface::eval::Scorecard> card;
  steadiface::Status s = steadiface::eval::MakeScorecard(sim, po, &card);
  steadiface::CameraModel model;
  steadiface::OutputGeometry output;
  if (s.ok()) s = MakeOutputGeometry(sim.intrinsics(), po, &model, &output);
  if (!s.ok()) return s;
  // Output px per normalized unit (the output map is a scale and a shift).
  const double scale = (output.VirtualToOutputPixel(Eigen::Vector2d(1.0, 0.0)) -
                        output.VirtualToOutputPixel(Eigen::Vector2d::Zero()))
                           .norm();
  std::ofstream csv(path);
  csv << "t,bg_head_x,bg_head_y,head_valid,reach_px\n";
  for (size_t i = 0; i < frames.size(); ++i) {
    const steadiface::StabilizerFrame& f = frames[i];
    steadiface::eval::FrameWarp w;
    w.kind = steadiface::eval::FrameWarp::Kind::kPose;
    w.R_v = f.background.valid ? f.background.R_v : f.R_v;
    w.t = f.background.valid ? f.background.t : f.t;
    w.rows = f.rows;
    card->Add(static_cast<int>(i), w);
    const auto& p = card->samples().back();
    csv << p.t << "," << p.head_out.x() << "," << p.head_out.y() << "," << p.head_valid << ","
        << f.subject_reach * scale << "\n";
  }
  return csv ? steadiface::Status::Ok() : steadiface::Status::Error("cannot write " + path);
}

// Per frame: the time and the radii of eval::FeasibleOffsets in 72
// directions (5 degrees apart, from +x towards +y) [input px].
steadiface::Status WriteFeasibleSet(
    const steadiface::CameraIntrinsics& intrinsics,
    const steadiface::PipelineOptions& po,
    const std::vector<steadiface::StabilizerFrame>& frames,
    const std::string& path, const std::vector<Eigen::Vector2d>& heads,
    double max_roll) {
  steadiface::CameraModel model;
  steadiface::OutputGeometry output;
  const steadiface::Status s = MakeOutputGeometry(intrinsics, po, &model, &output);
  if (!s.ok()) return s;
  const steadiface::eval::FeasibleOffsets feasible(
      model, output, po.stabilizer.terms.protrusion_samples_per_edge);
  std::ofstream csv(path);
  csv << "t";
  for (int k = 0; k < 72; ++k) csv << ",r" << 5 * k;
  csv << "\n";
  for (const steadiface::StabilizerFrame& f : frames) {
    csv << steadiface::ToSeconds(f.stamp);
    for (double r : feasible.Radii(f.rows, f.R_r, 72)) csv << "," << r;
    csv << "\n";
  }
  if (!csv) return steadiface::Status::Error("cannot write " + path);
  if (!(max_roll > 0.0)) return steadiface::Status::Ok();
  // With --feasible-roll: the same per frame for a window that also rolls,
  // every 0.025 rad within +-max_roll, and where the true head moves when it
  // does (NaN where it cannot be projected), one row per frame and roll.
  const std::string roll_path = path.substr(0, path.size() - 4) + "_roll.csv";
  std::ofstream rc(roll_path);
  rc << "t,roll,head_dx,head_dy";
  for (int k = 0; k < 72; ++k) rc << ",r" << 5 * k;
  rc << "\n";
  const int steps = static_cast<int>(std::floor(max_roll / 0.025 + 1e-9));
  for (size_t i = 0; i < frames.size(); ++i) {
    const steadiface::StabilizerFrame& f = frames[i];
    for (int j = -steps; j <= steps; ++j) {
      const double roll = 0.025 * j;
      Eigen::Vector2d shift(NAN, NAN);
      if (i < heads.size() && heads[i].allFinite() &&
          !feasible.RollShift(f.rows, f.R_r, roll, heads[i], &shift)) {
        shift = Eigen::Vector2d(NAN, NAN);
      }
      rc << steadiface::ToSeconds(f.stamp) << "," << roll << "," << shift.x()
         << "," << shift.y();
      for (double r : feasible.Radii(
               f.rows, steadiface::eval::FeasibleOffsets::Rolled(f.R_r, roll),
               72)) {
        rc << "," << r;
      }
      rc << "\n";
    }
  }
  if (!rc) return steadiface::Status::Error("cannot write " + roll_path);
  return steadiface::Status::Ok();
}

int Usage() {
  // clang-format off
  std::cerr << "usage: steadiface_evaluate --data DIR --out DIR [--presets a,b]\n"
               "       [--methods none,gyro-only,steadiface,steadiface-layered,none/video,\n"
               "        steadiface/video,ffmpeg-vidstab,ffmpeg-deshake] [--duration S]\n"
               "       [--size WxH] [--seed N] [--render] [--crop R]\n"
               "       [--band W] [--band-inside F] [--outline-margin CELLS] [--max-offset C] [--offset-lowpass HZ]\n"
               "       [--yield-to-background] (the layered warp's warp/layered/* options,\n"
               "         for sweeps; the last sets yield_to_subject false)\n"
               "       [--offset-error S] [--readout-error S] (misconfigure the IMU timing)\n"
               "       [--gyro-scale K] [--gyro-speed K] (presets with the recorded gyro\n"
               "         trace: scale its rotation, or play it K times as fast)\n"
               "       [--search-interval S] (face.search_interval: full-frame face search\n"
               "         at most once per S while no face is locked; 0 = every frame)\n"
               "       [--head-distance M] (the subject's distance [m]: robot at 2.75 m\n"
               "         shows a 30 px face)\n"
               "       [--crop-mode fixed|dynamic] (output.crop: the fixed crop ratio, or the\n"
               "         dynamic crop between --widest R and it; default: the package's)\n"
               "       [--horizon off|level|lock] (output.horizon: the roll against the\n"
               "         accelerometer's gravity)\n"
               "       [--rotation-source imu|visual] (visual: the camera's rotation from\n"
               "         the video, the IMU unused)\n"
               "       [--subject-reach R] (stabilizer.subject_reach, layered: H within R jaw\n"
               "         widths of where the background layer shows the face)\n"
               "       [--reach-lowpass HZ] [--reach-hold F] (stabilizer.subject_reach_lowpass,\n"
               "         subject_reach_hold: H follows the slow part of that position)\n"
               "       [--head-w-stay W] [--head-d-ref D] (head.w_stay, head.d_ref: the\n"
               "         head target's smoothing, Eq. 1)\n"
               "       [--feasible-set] (per stabilizer method also feasible_<preset>_<method>.csv:\n"
               "         per frame, the crop-window shifts the margin allows, rolling shutter\n"
               "         included, in 72 directions [input px], for scripts/analysis/crop_bound.py)\n"
               "       [--face-core CELLS] (warp/layered/face_core)\n"
               "       [--reach-tube] (layered: also reach_<preset>_<method>.csv: per frame,\n"
               "         the true head through the background layer's pose and the radius\n"
               "         H was held within there, both in output px; for\n"
               "         scripts/analysis/reach_bound.py)\n"
               "       [--feasible-roll MAX] (with --feasible-set, also\n"
               "         feasible_<preset>_<method>_roll.csv: the same for a window that also\n"
               "         rolls, every 0.025 rad within +-MAX, and the true head's move when it\n"
               "         does; for crop_bound.py --feasible-roll)\n";
  // clang-format on
  return 2;
}


// The view's flags: the crop mode and the horizon, and their tuning
// (NaN, -1 or empty: the package's default).
struct ViewFlags {
  int crop_mode = -1;      // --crop-mode: 0 fixed, 1 dynamic
  std::string horizon;     // --horizon: off, level or lock
  double level_weight = NAN, lock_weight = NAN;   // horizon.level_weight, lock_weight
  double gravity_warmup = NAN, gravity_tau = NAN;  // horizon.warmup, time_constant
  double widest = NAN;     // output.dynamic.widest_crop_ratio
  bool start_tight = false;  // output.dynamic.start_wide false
  double shake_hz = NAN, headroom = NAN;  // output.dynamic.shake_path_hz, headroom
  // output.dynamic.max_widen_rate, max_tighten_rate, max_widen_accel
  double widen_rate = NAN, tighten_rate = NAN, zoom_accel = NAN;
};

void AddViewFlags(steadiface::CommandLine* cl, ViewFlags* v) {
  cl->Value("--crop-mode", "fixed or dynamic", [v](const std::string& s) {
    v->crop_mode = s == "dynamic" ? 1 : 0;
    return s == "fixed" || s == "dynamic";
  });
  cl->Value("--horizon", "off, level or lock", [v](const std::string& s) {
    v->horizon = s;
    steadiface::HorizonMode m;
    return steadiface::ParseHorizonMode(s, &m).ok();
  });
  cl->Double("--level-weight", &v->level_weight).Double("--lock-weight", &v->lock_weight);
  cl->Double("--gravity-warmup", &v->gravity_warmup).Double("--gravity-tau", &v->gravity_tau);
  cl->Double("--widest", &v->widest).Flag("--start-tight", &v->start_tight);
  cl->Double("--shake-hz", &v->shake_hz).Double("--headroom", &v->headroom);
  cl->Double("--widen-rate", &v->widen_rate).Double("--tighten-rate", &v->tighten_rate);
  cl->Double("--zoom-accel", &v->zoom_accel);
}

void ApplyViewFlags(const ViewFlags& v, steadiface::PipelineOptions* po) {
  auto set = [](double flag, double* field) {
    if (std::isfinite(flag)) *field = flag;
  };
  if (v.crop_mode >= 0) {
    po->crop.mode = v.crop_mode == 1 ? steadiface::CropMode::kDynamic : steadiface::CropMode::kFixed;
  }
  if (!v.horizon.empty()) steadiface::ParseHorizonMode(v.horizon, &po->horizon.mode);
  if (v.start_tight) po->crop.start_wide = false;
  set(v.widest, &po->crop.widest_crop_ratio);
  set(v.level_weight, &po->horizon.level_weight);
  set(v.lock_weight, &po->horizon.lock_weight);
  set(v.gravity_warmup, &po->horizon.warmup_s);
  set(v.gravity_tau, &po->horizon.time_constant_s);
  set(v.shake_hz, &po->crop.shake_path_hz);
  set(v.headroom, &po->crop.headroom);
  set(v.widen_rate, &po->crop.max_widen_rate);
  set(v.tighten_rate, &po->crop.max_tighten_rate);
  set(v.zoom_accel, &po->crop.max_widen_accel);
}

}  // namespace

// --average15 N: writes each method's output frame N (<prefix>_frame.png)
// and the mean of frames N-7 .. N+7 (<prefix>_average15.png): a steady
// background or face is sharp in the average, one that swims is blurred.
class FrameAverager {
 public:
  FrameAverager(std::string prefix, int centre) : prefix_(std::move(prefix)), centre_(centre) {}
  steadiface::Status Add(const cv::Mat& frame) {
    const int i = index_++;
    if (i == centre_) cv::imwrite(prefix_ + "_frame.png", frame);
    if (i < centre_ - 7 || i > centre_ + 7) return steadiface::Status::Ok();
    cv::Mat f;
    frame.convertTo(f, CV_32F);
    if (sum_.empty()) {
      sum_ = f;
    } else {
      sum_ += f;
    }
    if (i == centre_ + 7) {
      cv::Mat mean;
      sum_.convertTo(mean, CV_8U, 1.0 / 15.0);
      cv::imwrite(prefix_ + "_average15.png", mean);
    }
    return steadiface::Status::Ok();
  }

 private:
  std::string prefix_;
  int centre_ = 0, index_ = 0;
  cv::Mat sum_;
};

// One preset's composite figures: a markdown row and a CSV row.
std::pair<std::string, std::string> CompositeRow(const std::string& preset,
                                                 const steadiface::eval::CompositeQualityScore& q) {
  auto f = [](double v, const char* fmt) {
    if (!std::isfinite(v)) return std::string("nan");
    char b[64];
    std::snprintf(b, sizeof(b), fmt, v);
    return std::string(b);
  };
  std::ostringstream md, csv;
  md << "| " << preset << " | " << q.frames << " | " << f(q.matte_iou_mean, "%.3f") << " | "
     << f(q.matte_iou_min, "%.3f") << " (" << q.matte_iou_min_frame << ") | "
     << f(q.matte_iou_min_settled, "%.3f") << " (" << q.matte_iou_min_settled_frame << ") | "
     << f(q.plate_mae, "%.2f") << " (" << f(q.ideal_plate_mae, "%.2f") << ") | "
     << f(q.plate_pixels, "%.0f") << " | "
     << f(q.fallback_share, "%.3f") << " | " << f(q.uncovered_mae, "%.2f") << " ("
     << f(q.uncovered_pixels, "%.0f") << ") | " << f(q.matte_change, "%.4f") << " | "
     << f(q.truth_change, "%.4f") << " | " << f(q.edge_error_px, "%.2f") << " | "
     << f(q.edge_max_step_px, "%.2f") << " | " << f(q.mog2_iou_mean, "%.3f") << " | "
     << f(q.knn_iou_mean, "%.3f") << " |\n";
  csv << preset << "," << q.frames << "," << f(q.matte_iou_mean, "%.4f") << ","
      << f(q.matte_iou_min, "%.4f") << "," << q.matte_iou_min_frame << ","
      << f(q.matte_iou_min_settled, "%.4f") << "," << q.matte_iou_min_settled_frame << ","
      << f(q.plate_mae, "%.3f") << "," << f(q.ideal_plate_mae, "%.3f") << ","
      << f(q.plate_pixels, "%.0f") << ","
      << f(q.fallback_share, "%.4f") << "," << f(q.uncovered_mae, "%.3f") << ","
      << f(q.uncovered_pixels, "%.0f") << "," << f(q.matte_change, "%.5f") << ","
      << f(q.truth_change, "%.5f") << "," << f(q.edge_error_px, "%.3f") << ","
      << f(q.edge_max_step_px, "%.3f") << "," << f(q.mog2_iou_mean, "%.4f") << ","
      << f(q.knn_iou_mean, "%.4f") << "\n";
  return {md.str(), csv.str()};
}

int main(int argc, char** argv) {
  std::string data, out_dir;
  std::vector<std::string> presets = steadiface::sim::PresetNames();
  std::vector<std::string> methods;  // empty: the default set
  double duration = NAN;  // NaN: 3 s, a recorded trace's whole length
  int width = 640, height = 360;
  uint64_t seed = 1;
  bool render = false;
  double crop = NAN;  // NaN: the package default
  steadiface::LayerBlendOptions blend;  // --band etc.
  // Deliberate misconfiguration of the camera-IMU timing [s] (calibration
  // studies): added to imu/time_offset and camera/readout_time.
  double offset_error = 0.0, readout_error = 0.0;
  // The recorded trace's scale and playback speed (NaN: the preset's).
  double gyro_scale = NAN, gyro_speed = NAN;
  double search_interval = NAN;  // face.search_interval [s]; NaN: the default
  double head_distance = NAN;    // the subject's distance [m]; NaN: the preset's
  bool visual_rotation = false;  // --rotation-source visual
  ViewFlags view;                // --crop-mode, --horizon and their tuning
  double head_w_stay = NAN;      // head.w_stay [-]; NaN: the default
  double head_d_ref = NAN;       // head.d_ref [fraction of the width]; NaN: the default
  double subject_reach = 0.0;    // stabilizer.subject_reach [jaw widths]; 0: off
  double reach_lowpass = NAN;    // stabilizer.subject_reach_lowpass_hz (NaN: default)
  double reach_hold = NAN;       // stabilizer.subject_reach_hold (NaN: default)
  bool feasible_set = false;     // --feasible-set: write feasible_<preset>_<method>.csv
  double feasible_roll = 0.0;    // --feasible-roll MAX [rad]; 0: none
  bool reach_tube = false;       // --reach-tube: write reach_<preset>_<method>.csv
  bool composite_frames = false;  // --composite-frames: composite_<preset>_<frame>.png
  int average_at = -1;  // --average15 N: <preset>_<method>_frame.png and _average15.png
  steadiface::CommandLine cl;
  cl.String("--data", &data).String("--out", &out_dir);
  cl.Value("--presets", "a comma-separated list",
           [&](const std::string& v) { return !(presets = Split(v)).empty(); });
  cl.Value("--methods", "a comma-separated list",
           [&](const std::string& v) { return !(methods = Split(v)).empty(); });
  cl.Double("--duration", &duration).UInt64("--seed", &seed).Flag("--render", &render);
  cl.Double("--crop", &crop).Double("--offset-error", &offset_error);
  cl.Double("--readout-error", &readout_error).Double("--gyro-scale", &gyro_scale);
  cl.Double("--gyro-speed", &gyro_speed).Double("--search-interval", &search_interval);
  cl.Double("--head-distance", &head_distance);
  cl.Value("--rotation-source", "imu or visual", [&](const std::string& v) {
    visual_rotation = v == "visual";
    return v == "imu" || v == "visual";
  });
  AddViewFlags(&cl, &view);
  cl.Double("--head-w-stay", &head_w_stay).Double("--head-d-ref", &head_d_ref);
  cl.Double("--subject-reach", &subject_reach).Double("--reach-lowpass", &reach_lowpass);
  cl.Double("--reach-hold", &reach_hold).Flag("--feasible-set", &feasible_set);
  cl.Double("--feasible-roll", &feasible_roll).Double("--band", &blend.band_width);
  cl.Double("--band-inside", &blend.band_inside);
  cl.Double("--outline-margin", &blend.outline_margin_cells);
  cl.Double("--face-core", &blend.face_core_cells).Flag("--reach-tube", &reach_tube);
  cl.Double("--max-offset", &blend.max_offset);
  cl.Flag("--composite-frames", &composite_frames);
  cl.Int("--average15", &average_at);
  steadiface::CompositeOptions composite;  // warp mode composite
  cl.Double("--matte-softness", &composite.matte.prior_softness);
  cl.Double("--matte-colour", &composite.matte.colour_weight);
  cl.Double("--matte-temporal", &composite.matte.temporal);
  cl.Double("--matte-plate-level", &composite.matte.plate_level);
  cl.Double("--matte-motion-level", &composite.matte.motion_level);
  cl.Double("--matte-search", &composite.matte.search_jaw_widths);
  cl.Double("--matte-motion-memory", &composite.matte.motion_memory);
  cl.Double("--plate-max-age", &composite.plate.max_age_s);
  cl.Int("--plate-distance", &composite.plate_distance_px);
  cl.Double("--plate-below", &composite.plate_below);
  cl.Int("--plate-row-step", &composite.plate_row_step);
  cl.Double("--plate-confidence", &composite.matte.plate_confidence);
  cl.Double("--plate-outlier", &composite.plate.outlier_level);
  cl.ClearFlag("--yield-to-background", &blend.yield_to_subject);
  cl.Double("--offset-lowpass", &blend.offset_lowpass_hz);
  cl.Value("--size", "WxH", [&](const std::string& v) {
    return std::sscanf(v.c_str(), "%dx%d", &width, &height) == 2;
  });
  std::string error;
  const steadiface::CommandLine::Result parsed = cl.Parse(argc, argv, &error);
  if (parsed == steadiface::CommandLine::Result::kHelp) {
    Usage();
    return 0;
  }
  if (parsed == steadiface::CommandLine::Result::kError) {
    std::cerr << "steadiface_evaluate: " << error << "\n";
    return Usage();
  }
  if (data.empty() || out_dir.empty()) return Usage();
  std::string ffmpeg_version;
  const bool have_ffmpeg = steadiface::eval::FfmpegAvailable(&ffmpeg_version);
  if (methods.empty()) {
    methods = {"none", "gyro-only", "steadiface"};
    if (have_ffmpeg) {
      // The peers, and the approximate scoring path applied to the input and
      // to steadiface's output, so its error can be read off the table.
      methods.insert(methods.end(),
                     {"none/video", "steadiface/video", "ffmpeg-vidstab", "ffmpeg-deshake"});
    } else {
      std::cerr << "ffmpeg with vidstab/deshake not found: peer baselines skipped\n";
    }
  }
  for (const std::string& name : methods) {
    if (name != "none" && name != "gyro-only" && name != "steadiface" &&
        name != "steadiface-layered" && name != "steadiface-layered/video" && name != "none/video" &&
        name != "steadiface-composite" && name != "steadiface-composite/video" &&
        name != "steadiface/video" && name != "gyro-only/video" && name != "ffmpeg-vidstab" &&
        name != "ffmpeg-deshake") {
      std::cerr << "unknown method " << name << "\n";
      return 2;
    }
    if (name.compare(0, 7, "ffmpeg-") == 0 && !have_ffmpeg) {
      std::cerr << "method " << name << " needs ffmpeg with the vidstab and deshake filters\n";
      return 2;
    }
  }
  mkdir(out_dir.c_str(), 0755);
  std::ofstream json(out_dir + "/report.json");
  auto jnum = [](double v) {
    std::ostringstream o;
    if (std::isfinite(v)) o << v; else o << "null";
    return o.str();
  };
  json << "{\n  \"duration_s\": " << jnum(duration) << ",\n  \"size\": [" << width << ", "
       << height << "],\n  \"seed\": " << seed << ",\n  \"ffmpeg\": \""
       << (have_ffmpeg ? ffmpeg_version : "") << "\",\n  \"results\": [\n";
  std::cout << "| preset | method | head jitter px | head jitter %diag | background jitter px"
               " | head-vs-bg jitter px | bg floor px"
               " | head stability | bg stability | cropping | distortion | undefined frames |"
               " solver p50 ms | face p50 ms | visible bg jitter px | line deviation px |"
               " line p99 px | min cell ratio | band jitter px | blend step px (max, 2nd diff) |"
               " head step px (max, 2nd diff) | head target step px (max, 2nd diff) | scoring |\n"
               "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  bool first = true;
  int failures = 0;
  std::vector<std::pair<std::string, std::string>> composite_rows;  // table, csv
  auto fmt = [](const char* f, double v) {
    if (!std::isfinite(v)) return std::string("–");
    char b[64];
    std::snprintf(b, sizeof(b), f, v);
    return std::string(b);
  };
  for (const std::string& preset : presets) {
    steadiface::sim::SimulatorOptions so;
    so.data_dir = data;
    so.duration_s = std::isfinite(duration) ? duration : 3.0;
    so.width = width;
    so.height = height;
    so.seed = seed;
    steadiface::Status s = steadiface::sim::ApplyPreset(preset, &so);
    if (std::isfinite(gyro_scale)) so.real_gyro_scale = gyro_scale;
    if (std::isfinite(gyro_speed)) so.real_gyro_speed = gyro_speed;
    if (std::isfinite(head_distance)) so.head.distance_m = head_distance;
    std::unique_ptr<steadiface::sim::Simulator> sim;
    if (s.ok()) s = steadiface::sim::Simulator::Create(so, &sim);
    if (s.ok() && !std::isfinite(duration) && sim->real_gyro_span_s() > so.duration_s) {
      // The whole recorded trace once (a 3 s slice of it is a poor sample).
      so.duration_s = std::floor(10.0 * sim->real_gyro_span_s()) / 10.0;
      s = steadiface::sim::Simulator::Create(so, &sim);
    }
    if (!s.ok()) {
      std::cerr << "preset " << preset << ": " << s.message() << "\n";
      ++failures;
      continue;
    }
    std::string input_dir, input_video;  // lossless input for the ffmpeg peers, once per preset
    for (const std::string& name : methods) {
      const bool video = name.size() > 6 && name.compare(name.size() - 6, 6, "/video") == 0;
      const bool peer = name.compare(0, 7, "ffmpeg-") == 0;
      const std::string base = video ? name.substr(0, name.size() - 6) : name;
      steadiface::eval::Score sc;
      double solver = NAN, face = NAN, peer_ms = NAN;
      double face_fraction = NAN;
      std::unique_ptr<steadiface::eval::VideoScorer> vs;
      if (video || peer) {
        steadiface::eval::VideoScorerOptions vo;
        vo.fps = so.fps;
        s = steadiface::eval::VideoScorer::Create(sim->intrinsics(), vo, &vs);
        if (!s.ok()) {
          std::cerr << name << ": " << s.message() << "\n";
          return 1;
        }
      }
      if (peer) {
        if (input_video.empty()) {
          char tmpl[] = "/tmp/steadiface_eval_XXXXXX";
          if (mkdtemp(tmpl) == nullptr) {
            std::cerr << "cannot create a temporary directory\n";
            return 1;
          }
          input_dir = tmpl;
          const std::string path = input_dir + "/input.mkv";
          steadiface::eval::LosslessVideoWriter w;
          s = w.Open(path, width, height, so.fps);
          cv::Mat frame;
          steadiface::sim::SimTruth truth;
          for (int i = 0; s.ok() && i < sim->num_frames(); ++i) {
            s = sim->Render(i, &frame, &truth);
            if (s.ok()) s = w.Write(frame);
          }
          const steadiface::Status c = w.Close();
          if (s.ok()) s = c;
          if (!s.ok()) {
            std::cerr << preset << ": lossless input: " << s.message() << "\n";
            ++failures;
            continue;
          }
          input_video = path;
        }
        const auto fm = name == "ffmpeg-vidstab" ? steadiface::eval::FfmpegMethod::kVidstab
                                                 : steadiface::eval::FfmpegMethod::kDeshake;
        // Time ffmpeg alone: collect its frames first, score afterwards.
        std::vector<cv::Mat> frames;
        double seconds = 0.0;
        s = steadiface::eval::RunFfmpegStabilizer(
            fm, input_video, width, height, input_dir,
            [&frames](const cv::Mat& f) {
              frames.push_back(f.clone());
              return steadiface::Status::Ok();
            },
            &seconds);
        for (size_t i = 0; s.ok() && i < frames.size(); ++i) s = vs->Add(frames[i]);
        if (s.ok()) peer_ms = 1000.0 * seconds / std::max<size_t>(1, frames.size());
      } else {
        const Method m = base == "none"                 ? Method::kNone
                         : base == "gyro-only"          ? Method::kGyroOnly
                         : base == "steadiface-layered" ? Method::kSteadifaceLayered
                         : base == "steadiface-composite" ? Method::kSteadifaceComposite
                                                        : Method::kSteadiface;
        steadiface::PipelineOptions po = steadiface::eval::OptionsFor(*sim, m);
        if (std::isfinite(crop)) po.warp.output.crop_ratio = crop;
        ApplyViewFlags(view, &po);
        if (std::isfinite(search_interval)) po.face.search_interval_s = search_interval;
        if (visual_rotation) po.rotation_source = steadiface::RotationSource::kVisual;
        if (std::isfinite(head_w_stay)) po.stabilizer.head.w_stay = head_w_stay;
        if (std::isfinite(head_d_ref)) po.stabilizer.head.d_ref = head_d_ref;
        po.stabilizer.subject_reach = subject_reach;
        if (std::isfinite(reach_lowpass)) po.stabilizer.subject_reach_lowpass_hz = reach_lowpass;
        if (std::isfinite(reach_hold)) po.stabilizer.subject_reach_hold = reach_hold;
        po.warp.layered.blend = blend;
        po.composite = composite;
        po.imu.imu_time_offset_s += offset_error;
        po.shutter.readout_time_s = std::max(0.0, po.shutter.readout_time_s + readout_error);
        std::unique_ptr<steadiface::eval::Scorecard> card;
        s = steadiface::eval::MakeScorecard(*sim, po, &card);
        steadiface::eval::VideoScorer* vsp = vs.get();
        std::vector<steadiface::StabilizerFrame> stab_frames;
        steadiface::eval::CompositeQualityScore cq;
        std::unique_ptr<FrameAverager> avg;
        if (average_at >= 0 && !video) {
          avg.reset(new FrameAverager(out_dir + "/" + preset + "_" + name, average_at));
        }
        if (s.ok()) {
          FrameAverager* ap = avg.get();
          s = steadiface::eval::RunMethod(
              *sim, m, po, render || video || ap != nullptr, card.get(), &stab_frames,
              video ? std::function<steadiface::Status(const cv::Mat&)>(
                          [vsp](const cv::Mat& f) { return vsp->Add(f); })
              : ap != nullptr ? std::function<steadiface::Status(const cv::Mat&)>(
                                    [ap](const cv::Mat& f) { return ap->Add(f); })
                              : nullptr,
              m == Method::kSteadifaceComposite && !video ? &cq : nullptr,
              composite_frames ? out_dir + "/composite_" + preset : std::string());
        }
        if (s.ok() && m == Method::kSteadifaceComposite && !video) {
          composite_rows.push_back(CompositeRow(preset, cq));
        }
        if (s.ok() && !video) {
          sc = card->Compute();
          // Frames whose face entered E_f: found, passed every check, used.
          if (m != Method::kNone && m != Method::kGyroOnly && !stab_frames.empty()) {
            int used = 0;
            for (const auto& f : stab_frames) used += f.flags.face_used ? 1 : 0;
            face_fraction = static_cast<double>(used) / stab_frames.size();
          }
          for (const auto& st : sc.stage_ms) {
            if (st.first == "solver") solver = st.second.first;
            if (st.first == "face") face = st.second.first;
          }
          std::ofstream csv(out_dir + "/traj_" + preset + "_" + name + ".csv");
          csv << "t,head_in_x,head_in_y,head_out_x,head_out_y,head_valid,bg_out_x,bg_out_y,"
                 "virt_rx,virt_ry,virt_rz,real_rx,real_ry,real_rz,tx,ty,"
                 "crop_ratio,crop_need,w_fit,protrusion_search_s,previous_warp\n";
          // The stabilizer's own record (nan for "none"): the w_f in
          // effect, how far the protrusion search moved towards the real
          // pose (-1: it did not run) and whether the previous warp was reused.
          const auto& samples = card->samples();
          for (size_t i = 0; i < samples.size(); ++i) {
            const auto& p = samples[i];
            csv << p.t << "," << p.head_in.x() << "," << p.head_in.y() << "," << p.head_out.x()
                << "," << p.head_out.y() << "," << p.head_valid << "," << p.background_out.x()
                << "," << p.background_out.y() << "," << p.virtual_angle[0] << ","
                << p.virtual_angle[1] << "," << p.virtual_angle[2] << "," << p.real_angle[0]
                << "," << p.real_angle[1] << "," << p.real_angle[2] << "," << p.offset.x()
                << "," << p.offset.y() << "," << p.crop_ratio << "," << p.crop_need;
            if (i < stab_frames.size()) {
              const steadiface::StabilizerFrame& f = stab_frames[i];
              csv << "," << f.weights.fit << ","
                  << (f.flags.protrusion_search ? f.flags.protrusion_search_s : -1.0) << ","
                  << f.flags.previous_warp << "\n";
            } else {
              csv << ",nan,nan,nan\n";  // no stabilizer (input)
            }
          }
          if (reach_tube && m == Method::kSteadifaceLayered && s.ok()) {
            s = WriteReachTube(*sim, po, stab_frames,
                               out_dir + "/reach_" + preset + "_" + name + ".csv");
          }
          if (feasible_set && !stab_frames.empty()) {
            std::vector<Eigen::Vector2d> heads;  // the true head in the input
            for (const auto& p : card->samples()) heads.push_back(p.head_in);
            s = WriteFeasibleSet(
                sim->intrinsics(), po, stab_frames,
                out_dir + "/feasible_" + preset + "_" + name + ".csv", heads,
                feasible_roll);
          }
        }
      }
      if (!s.ok()) {
        std::cerr << preset << "/" << name << ": " << s.message() << "\n";
        ++failures;
        continue;
      }
      if (vs) {
        sc = vs->Compute();
        face_fraction = vs->face_fraction();
      }
      const std::string scoring = vs ? "approximate" : "exact";
      std::cout << "| " << preset << " | " << name << " | " << fmt("%.2f", sc.head_jitter_px)
                << " | " << fmt("%.3f", 100 * sc.head_jitter_frac) << " | "
                << fmt("%.2f", sc.background_jitter_px) << " | "
                << fmt("%.2f", sc.relative_jitter_px) << " | "
                << fmt("%.2f", sc.background_floor_px) << " | "
                << fmt("%.2f", sc.head_stability) << " | "
                << fmt("%.2f", sc.background_stability) << " | " << fmt("%.2f", sc.cropping)
                << " | " << fmt("%.3f", sc.distortion) << " | "
                << fmt("%.1f%%", 100 * sc.undefined_fraction) << " | " << fmt("%.3f", solver)
                << " | " << fmt("%.2f", face) << " | "
                << fmt("%.2f", sc.visible_background_jitter_px) << " | "
                << fmt("%.2f", sc.line_deviation_px) << " | "
                << fmt("%.2f", sc.line_deviation_p99_px) << " | " << fmt("%.3f", sc.min_cell_ratio)
                << " | " << fmt("%.2f", sc.band_jitter_px) << " | "
                << fmt("%.2f", sc.blend_max_step_px) << ", " << fmt("%.2f", sc.blend_max_accel_px)
                << " | " << fmt("%.2f", sc.head_max_step_px) << ", "
                << fmt("%.2f", sc.head_max_accel_px)
                << " | " << fmt("%.2f", sc.head_target_max_step_px) << ", "
                << fmt("%.2f", sc.head_target_max_accel_px) << " | " << scoring << " |"
                << std::endl;
      json << (first ? "" : ",\n") << "    {\"preset\": \"" << preset
           << "\", \"duration_s\": " << so.duration_s << ", \"method\": \"" << name
           << "\", \"scoring\": \"" << scoring << "\", \"frames\": " << sc.frames
           << ", \"head_jitter_px\": " << jnum(sc.head_jitter_px)
           << ", \"head_jitter_frac\": " << jnum(sc.head_jitter_frac)
           << ", \"background_jitter_px\": " << jnum(sc.background_jitter_px)
           << ", \"background_jitter_frac\": " << jnum(sc.background_jitter_frac)
           << ", \"relative_jitter_px\": " << jnum(sc.relative_jitter_px)
           << ", \"background_floor_px\": " << jnum(sc.background_floor_px)
           << ", \"head_stability\": " << jnum(sc.head_stability)
           << ", \"background_stability\": " << jnum(sc.background_stability)
           << ", \"cropping\": " << jnum(sc.cropping) << ", \"distortion\": " << jnum(sc.distortion)
           << ", \"kept_width_mean\": " << jnum(sc.kept_width_mean)
           << ", \"kept_width_min\": " << jnum(sc.kept_width_min)
           << ", \"kept_width_max_step\": " << jnum(sc.kept_width_max_step)
           << ", \"kept_width_rms_accel\": " << jnum(sc.kept_width_rms_accel)
           << ", \"output_roll_rms_deg\": " << jnum(sc.output_roll_rms_deg)
           << ", \"input_roll_rms_deg\": " << jnum(sc.input_roll_rms_deg)
           << ", \"undefined_fraction\": " << jnum(sc.undefined_fraction)
           << ", \"face_fraction\": " << jnum(face_fraction)
           << ", \"visible_background_jitter_px\": " << jnum(sc.visible_background_jitter_px)
           << ", \"line_deviation_px\": " << jnum(sc.line_deviation_px)
           << ", \"line_deviation_frame\": " << sc.line_deviation_frame
           << ", \"min_cell_ratio\": " << jnum(sc.min_cell_ratio)
           << ", \"min_cell_ratio_frame\": " << sc.min_cell_ratio_frame
           << ", \"p01_cell_ratio\": " << jnum(sc.p01_cell_ratio)
           << ", \"folded_cells\": " << sc.folded_cells
           << ", \"band_jitter_px\": " << jnum(sc.band_jitter_px)
           << ", \"line_deviation_p99_px\": " << jnum(sc.line_deviation_p99_px)
           << ", \"blend_max_step_px\": " << jnum(sc.blend_max_step_px)
           << ", \"blend_max_accel_px\": " << jnum(sc.blend_max_accel_px)
           << ", \"head_max_step_px\": " << jnum(sc.head_max_step_px)
           << ", \"head_max_accel_px\": " << jnum(sc.head_max_accel_px)
           << ", \"head_target_max_step_px\": " << jnum(sc.head_target_max_step_px)
           << ", \"head_target_max_accel_px\": " << jnum(sc.head_target_max_accel_px)
           << ", \"peer_wall_ms_per_frame\": " << jnum(peer_ms) << ", \"stage_ms\": {";
      for (size_t k = 0; k < sc.stage_ms.size(); ++k) {
        json << (k ? ", " : "") << "\"" << sc.stage_ms[k].first << "\": ["
             << sc.stage_ms[k].second.first << ", " << sc.stage_ms[k].second.second << "]";
      }
      json << "}}";
      first = false;
    }
    if (!input_dir.empty()) {
      std::remove((input_dir + "/input.mkv").c_str());
      rmdir(input_dir.c_str());
    }
  }
  json << "\n  ]\n}\n";
  if (!composite_rows.empty()) {
    std::ofstream csv(out_dir + "/composite_quality.csv");
    std::cout << "\n| preset | frames | matte IoU mean | matte IoU min (frame) |"
                 " min after 0.5 s (frame) | plate MAE grey (ideal plate) |"
                 " plate px | fallback share | uncovered MAE grey (px) | matte change | truth change |"
                 " edge error px | edge max step px | MOG2 IoU | KNN IoU |\n"
                 "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    csv << "preset,frames,matte_iou_mean,matte_iou_min,matte_iou_min_frame,matte_iou_min_settled,"
           "matte_iou_min_settled_frame,plate_mae,"
           "ideal_plate_mae,plate_px,"
           "fallback_share,uncovered_mae,uncovered_px,matte_change,truth_change,edge_error_px,"
           "edge_max_step_px,mog2_iou_mean,knn_iou_mean\n";
    for (const auto& r : composite_rows) {
      std::cout << r.first;
      csv << r.second;
    }
  }
  return failures == 0 ? 0 : 1;
}

#include "eval/evaluation_files.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "steadiface_core/eval/feasible_offsets.h"
#include "steadiface_core/eval/run_methods.h"

namespace steadiface {
namespace eval {
namespace {

// The camera model and output geometry a pipeline with `po` builds for
// `intrinsics`.
Status MakeOutputGeometry(const CameraIntrinsics& intrinsics,
                                      const PipelineOptions& po,
                                      CameraModel* model,
                                      OutputGeometry* output) {
  const Status s = CameraModel::Create(intrinsics, po.camera, model);
  return s.ok() ? OutputGeometry::Create(*model, po.warp.output, output) : s;
}

}  // namespace

// Per frame of a layered run: the time, the true head centre through the
// background layer's pose (where the background layer shows it) and
// whether it is in view [output px], and the radius of the disc the
// stabilizer held H within around where it saw the face there (0: none)
// [output px]: the tube any head that leaves the background alone must stay
// in, for scripts/analysis/reach_bound.py.
Status WriteReachTube(const sim::Simulator& sim,
                                  const PipelineOptions& po,
                                  const std::vector<StabilizerFrame>& frames,
                                  const std::string& path) {
  std::unique_ptr<Scorecard> card;
  Status s = MakeScorecard(sim, po, &card);
  CameraModel model;
  OutputGeometry output;
  if (s.ok()) s = MakeOutputGeometry(sim.intrinsics(), po, &model, &output);
  if (!s.ok()) return s;
  // Output px per normalized unit (the output map is a scale and a shift).
  const double scale = (output.VirtualToOutputPixel(Eigen::Vector2d(1.0, 0.0)) -
                        output.VirtualToOutputPixel(Eigen::Vector2d::Zero()))
                           .norm();
  std::ofstream csv(path);
  csv << "t,bg_head_x,bg_head_y,head_valid,reach_px\n";
  for (size_t i = 0; i < frames.size(); ++i) {
    const StabilizerFrame& f = frames[i];
    FrameWarp w;
    w.kind = FrameWarp::Kind::kPose;
    w.R_v = f.background.valid ? f.background.R_v : f.R_v;
    w.t = f.background.valid ? f.background.t : f.t;
    w.rows = f.rows;
    card->Add(static_cast<int>(i), w);
    const auto& p = card->samples().back();
    csv << p.t << "," << p.head_out.x() << "," << p.head_out.y() << "," << p.head_valid << ","
        << f.subject_reach * scale << "\n";
  }
  return csv ? Status::Ok() : Status::Error("cannot write " + path);
}

// Per frame: the time and the radii of eval::FeasibleOffsets in 72
// directions (5 degrees apart, from +x towards +y) [input px].
Status WriteFeasibleSet(
    const CameraIntrinsics& intrinsics,
    const PipelineOptions& po,
    const std::vector<StabilizerFrame>& frames,
    const std::string& path, const std::vector<Eigen::Vector2d>& heads,
    double max_roll) {
  CameraModel model;
  OutputGeometry output;
  const Status s = MakeOutputGeometry(intrinsics, po, &model, &output);
  if (!s.ok()) return s;
  const FeasibleOffsets feasible(
      model, output, po.stabilizer.terms.protrusion_samples_per_edge);
  std::ofstream csv(path);
  csv << "t";
  for (int k = 0; k < 72; ++k) csv << ",r" << 5 * k;
  csv << "\n";
  for (const StabilizerFrame& f : frames) {
    csv << ToSeconds(f.stamp);
    for (double r : feasible.Radii(f.rows, f.R_r, 72)) csv << "," << r;
    csv << "\n";
  }
  if (!csv) return Status::Error("cannot write " + path);
  if (!(max_roll > 0.0)) return Status::Ok();
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
    const StabilizerFrame& f = frames[i];
    for (int j = -steps; j <= steps; ++j) {
      const double roll = 0.025 * j;
      Eigen::Vector2d shift(NAN, NAN);
      if (i < heads.size() && heads[i].allFinite() &&
          !feasible.RollShift(f.rows, f.R_r, roll, heads[i], &shift)) {
        shift = Eigen::Vector2d(NAN, NAN);
      }
      rc << ToSeconds(f.stamp) << "," << roll << "," << shift.x()
         << "," << shift.y();
      for (double r : feasible.Radii(
               f.rows, FeasibleOffsets::Rolled(f.R_r, roll),
               72)) {
        rc << "," << r;
      }
      rc << "\n";
    }
  }
  if (!rc) return Status::Error("cannot write " + roll_path);
  return Status::Ok();
}

Status FrameAverager::Add(const cv::Mat& frame) {
  const int i = index_++;
  if (i == centre_) cv::imwrite(prefix_ + "_frame.png", frame);
  if (i < centre_ - 7 || i > centre_ + 7) return Status::Ok();
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
  return Status::Ok();
}


// One preset's composite figures: a markdown row and a CSV row.
std::pair<std::string, std::string> CompositeRow(const std::string& preset,
                                                 const CompositeQualityScore& q) {
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


Status WriteTrajectory(const std::string& path, const std::vector<Scorecard::Sample>& samples,
                       const std::vector<StabilizerFrame>& frames) {
  std::ofstream csv(path);
  csv << "t,head_in_x,head_in_y,head_out_x,head_out_y,head_valid,bg_out_x,bg_out_y,"
         "virt_rx,virt_ry,virt_rz,real_rx,real_ry,real_rz,tx,ty,"
         "crop_ratio,crop_need,w_fit,protrusion_search_s,previous_warp,C_x,C_y,H_x,H_y\n";
  // The stabilizer's own record (nan for "none"): the w_f in effect, how
  // far the protrusion search moved towards the real pose (-1: it did not
  // run), whether the previous warp was reused, and the landmark centre C
  // and head target H it was handed [normalized; nan without a target].
  for (size_t i = 0; i < samples.size(); ++i) {
    const auto& p = samples[i];
    csv << p.t << "," << p.head_in.x() << "," << p.head_in.y() << "," << p.head_out.x() << ","
        << p.head_out.y() << "," << p.head_valid << "," << p.background_out.x() << ","
        << p.background_out.y() << "," << p.virtual_angle[0] << "," << p.virtual_angle[1] << ","
        << p.virtual_angle[2] << "," << p.real_angle[0] << "," << p.real_angle[1] << ","
        << p.real_angle[2] << "," << p.offset.x() << "," << p.offset.y() << "," << p.crop_ratio
        << "," << p.crop_need;
    if (i < frames.size()) {
      const StabilizerFrame& f = frames[i];
      csv << "," << f.weights.fit << ","
          << (f.flags.protrusion_search ? f.flags.protrusion_search_s : -1.0) << ","
          << f.flags.previous_warp;
      if (f.has_target) {
        csv << "," << f.C.x() << "," << f.C.y() << "," << f.H.x() << "," << f.H.y() << "\n";
      } else {
        csv << ",nan,nan,nan,nan\n";
      }
    } else {
      csv << ",nan,nan,nan,nan,nan,nan,nan\n";  // no stabilizer (input)
    }
  }
  return csv ? Status::Ok() : Status::Error("cannot write " + path);
}

std::string JsonNumber(double v) {
  std::ostringstream o;
  if (std::isfinite(v)) o << v; else o << "null";
  return o.str();
}

namespace {

std::string Fmt(const char* f, double v) {
  if (!std::isfinite(v)) return std::string("–");
  char b[64];
  std::snprintf(b, sizeof(b), f, v);
  return std::string(b);
}

// exact: the method's own warp; aligned: a peer's output aligned to the
// input frame by frame; approximate: measured on the output video.
const char* ScoringName(const RunFigures& run) {
  return run.approximate ? "approximate" : run.aligned ? "aligned" : "exact";
}

}  // namespace

std::string TableHeader() {
  return "| preset | method | head jitter px | head jitter %diag | background jitter px"
         " | head-vs-bg jitter px | bg floor px"
         " | head stability | bg stability | cropping | distortion | undefined frames |"
         " solver p50 ms | face p50 ms | visible bg jitter px | line deviation px |"
         " line p99 px | min cell ratio | band jitter px | blend step px (max, 2nd diff) |"
         " head step px (max, 2nd diff) | head target step px (max, 2nd diff) | scoring |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
}

std::string TableRow(const std::string& preset, const std::string& method, const Score& sc,
                     const RunFigures& run) {
  std::ostringstream o;
  o << "| " << preset << " | " << method << " | " << Fmt("%.2f", sc.head_jitter_px) << " | "
    << Fmt("%.3f", 100 * sc.head_jitter_frac) << " | " << Fmt("%.2f", sc.background_jitter_px)
    << " | " << Fmt("%.2f", sc.relative_jitter_px) << " | "
    << Fmt("%.2f", sc.background_floor_px) << " | " << Fmt("%.2f", sc.head_stability) << " | "
    << Fmt("%.2f", sc.background_stability) << " | " << Fmt("%.2f", sc.cropping) << " | "
    << Fmt("%.3f", sc.distortion) << " | " << Fmt("%.1f%%", 100 * sc.undefined_fraction)
    << " | " << Fmt("%.3f", run.solver_ms) << " | " << Fmt("%.2f", run.face_ms) << " | "
    << Fmt("%.2f", sc.visible_background_jitter_px) << " | "
    << Fmt("%.2f", sc.line_deviation_px) << " | " << Fmt("%.2f", sc.line_deviation_p99_px)
    << " | " << Fmt("%.3f", sc.min_cell_ratio) << " | " << Fmt("%.2f", sc.band_jitter_px)
    << " | " << Fmt("%.2f", sc.blend_max_step_px) << ", " << Fmt("%.2f", sc.blend_max_accel_px)
    << " | " << Fmt("%.2f", sc.head_max_step_px) << ", " << Fmt("%.2f", sc.head_max_accel_px)
    << " | " << Fmt("%.2f", sc.head_target_max_step_px) << ", "
    << Fmt("%.2f", sc.head_target_max_accel_px) << " | " << ScoringName(run) << " |";
  return o.str();
}

namespace {

// report.json's figures of a score, each as ", \"name\": value".
std::string JsonScoreFields(const Score& sc) {
  std::ostringstream o;
  auto num = [&o](const char* name, double v) { o << ", \"" << name << "\": " << JsonNumber(v); };
  num("head_jitter_px", sc.head_jitter_px);
  num("head_jitter_frac", sc.head_jitter_frac);
  num("background_jitter_px", sc.background_jitter_px);
  num("background_jitter_frac", sc.background_jitter_frac);
  num("relative_jitter_px", sc.relative_jitter_px);
  num("background_floor_px", sc.background_floor_px);
  num("head_stability", sc.head_stability);
  num("background_stability", sc.background_stability);
  num("cropping", sc.cropping);
  num("distortion", sc.distortion);
  num("kept_width_mean", sc.kept_width_mean);
  num("kept_width_min", sc.kept_width_min);
  num("kept_width_max_step", sc.kept_width_max_step);
  num("kept_width_rms_accel", sc.kept_width_rms_accel);
  num("output_roll_rms_deg", sc.output_roll_rms_deg);
  num("input_roll_rms_deg", sc.input_roll_rms_deg);
  num("undefined_fraction", sc.undefined_fraction);
  return o.str();
}

// The rest of the figures, after face_fraction.
std::string JsonDetailFields(const Score& sc) {
  std::ostringstream o;
  auto num = [&o](const char* name, double v) { o << ", \"" << name << "\": " << JsonNumber(v); };
  num("visible_background_jitter_px", sc.visible_background_jitter_px);
  num("visible_background_max_step_px", sc.visible_background_max_step_px);
  num("line_deviation_px", sc.line_deviation_px);
  o << ", \"line_deviation_frame\": " << sc.line_deviation_frame;
  num("min_cell_ratio", sc.min_cell_ratio);
  o << ", \"min_cell_ratio_frame\": " << sc.min_cell_ratio_frame;
  num("p01_cell_ratio", sc.p01_cell_ratio);
  o << ", \"folded_cells\": " << sc.folded_cells;
  num("band_jitter_px", sc.band_jitter_px);
  num("line_deviation_p99_px", sc.line_deviation_p99_px);
  num("blend_max_step_px", sc.blend_max_step_px);
  num("blend_max_accel_px", sc.blend_max_accel_px);
  num("head_max_step_px", sc.head_max_step_px);
  num("head_max_accel_px", sc.head_max_accel_px);
  num("head_target_max_step_px", sc.head_target_max_step_px);
  num("head_target_max_accel_px", sc.head_target_max_accel_px);
  num("rotation_error_deg", sc.rotation_error_deg);
  num("rotation_error_px", sc.rotation_error_px);
  num("rotation_error_max_deg", sc.rotation_error_max_deg);
  num("window_head_jitter_px", sc.window_head_jitter_px);
  num("window_background_jitter_px", sc.window_background_jitter_px);
  num("window_start_step_px", sc.window_start_step_px);
  num("window_end_step_px", sc.window_end_step_px);
  num("virtual_step_p95_px", sc.virtual_step_p95_px);
  return o.str();
}

}  // namespace

std::string JsonResult(const std::string& preset, const std::string& method, const Score& sc,
                       const RunFigures& run) {
  std::ostringstream o;
  o << "    {\"preset\": \"" << preset << "\", \"duration_s\": " << run.duration_s
    << ", \"method\": \"" << method << "\", \"scoring\": \"" << ScoringName(run)
    << "\", \"frames\": " << sc.frames
    << JsonScoreFields(sc) << ", \"face_fraction\": " << JsonNumber(run.face_fraction)
    << JsonDetailFields(sc) << ", \"peer_wall_ms_per_frame\": " << JsonNumber(run.peer_ms)
    << ", \"alignment_rms_px\": " << JsonNumber(run.alignment_rms_px)
    << ", \"alignment_min_inliers\": " << run.alignment_min_inliers
    << ", \"stage_ms\": {";
  for (size_t k = 0; k < sc.stage_ms.size(); ++k) {
    o << (k ? ", " : "") << "\"" << sc.stage_ms[k].first << "\": ["
      << sc.stage_ms[k].second.first << ", " << sc.stage_ms[k].second.second << "]";
  }
  o << "}}";
  return o.str();
}

void WriteCompositeTable(const std::vector<std::pair<std::string, std::string>>& rows,
                         const std::string& csv_path, std::ostream& out) {
  std::ofstream csv(csv_path);
  out << "\n| preset | frames | matte IoU mean | matte IoU min (frame) |"
         " min after 0.5 s (frame) | plate MAE grey (ideal plate) |"
         " plate px | fallback share | uncovered MAE grey (px) | matte change | truth change |"
         " edge error px | edge max step px | MOG2 IoU | KNN IoU |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  csv << "preset,frames,matte_iou_mean,matte_iou_min,matte_iou_min_frame,matte_iou_min_settled,"
         "matte_iou_min_settled_frame,plate_mae,"
         "ideal_plate_mae,plate_px,"
         "fallback_share,uncovered_mae,uncovered_px,matte_change,truth_change,edge_error_px,"
         "edge_max_step_px,mog2_iou_mean,knn_iou_mean\n";
  for (const auto& r : rows) {
    out << r.first;
    csv << r.second;
  }
}

}  // namespace eval
}  // namespace steadiface

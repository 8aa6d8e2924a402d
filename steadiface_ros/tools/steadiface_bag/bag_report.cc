#include "steadiface_bag/bag_report.h"

#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <vector>

#include "steadiface_core/common/high_pass_rms.h"
#include "steadiface_core/common/percentile.h"
#include "steadiface_core/common/so3.h"
#include "steadiface_ros/msg_conversion.h"

namespace steadiface_bag {
namespace {

// The scorecard's definition of jitter: > cutoff RMS, linear trend removed.
using steadiface::HighPassRms;
using steadiface::Percentile;

// "gyro-only", "steadiface", "steadiface-layered" or "steadiface-composite"
// (warp/mode layered or composite).
std::string MethodName(const ReportInputs& r, const BagSink& sink) {
  if (r.gyro_only) return "gyro-only";
  const std::string mode = sink.states.empty() ? "global" : sink.states.back().warp_mode;
  if (mode == "layered" || mode == "composite") return "steadiface-" + mode;
  return "steadiface";
}

// The plot trajectories of one scorecard (scripts/plot_report.py).
void WritePlot(const std::string& path, const steadiface::eval::Scorecard& card) {
  std::ofstream f(path);
  f << "t,head_in_x,head_in_y,head_out_x,head_out_y,head_valid,bg_out_x,bg_out_y,"
       "virt_rx,virt_ry,virt_rz,real_rx,real_ry,real_rz,tx,ty\n";
  const auto& samples = card.samples();
  const double t0 = samples.empty() ? 0.0 : samples.front().t;
  for (const auto& s : samples) {
    const Eigen::Vector2d ho =
        s.head_valid ? s.head_out : Eigen::Vector2d::Constant(NAN);
    f << s.t - t0 << "," << s.head_in.x() << "," << s.head_in.y() << "," << ho.x() << ","
      << ho.y() << "," << s.head_valid << "," << s.background_out.x() << ","
      << s.background_out.y() << "," << s.virtual_angle[0] << "," << s.virtual_angle[1] << ","
      << s.virtual_angle[2] << "," << s.real_angle[0] << "," << s.real_angle[1] << ","
      << s.real_angle[2] << "," << s.offset.x() << "," << s.offset.y() << "\n";
  }
}

std::string Num(double v) {
  std::ostringstream o;
  o.precision(6);
  if (std::isfinite(v)) o << v; else o << "null";
  return o.str();
}

// The ground-truth block: eval::Scorecard's figures (steadiface_evaluate's
// scorer) for the input and the output, on the frames both saw.
std::string TruthJson(const ReportInputs& r, const BagSink& sink) {
  const steadiface::eval::Score in = r.scorer->Input(), out = r.scorer->Output();
  if (!r.plot_dir.empty()) {
    WritePlot(r.plot_dir + "/traj_" + r.plot_name + "_" + MethodName(r, sink) + ".csv",
              r.scorer->output_card());
    if (!r.gyro_only) {
      WritePlot(r.plot_dir + "/traj_" + r.plot_name + "_none.csv", r.scorer->input_card());
    }
  }
  std::ostringstream tj;
  tj << ",\n  \"ground_truth\": {\"truth\": \"" << r.truth << "\""
     << ", \"scorer\": \"eval::Scorecard\", \"frames\": " << r.scorer->frames()
     << ", \"frames_not_in_truth\": " << r.scorer->unmatched()
     << ", \"scoring_time_s\": " << Num(r.scoring_s)
     << ", \"head_jitter_in_px\": " << Num(in.head_jitter_px)
     << ", \"head_jitter_out_px\": " << Num(out.head_jitter_px)
     << ", \"head_jitter_out_frac\": " << Num(out.head_jitter_frac)
     << ", \"background_jitter_in_px\": " << Num(in.background_jitter_px)
     << ", \"background_jitter_out_px\": " << Num(out.background_jitter_px)
     << ", \"visible_background_jitter_in_px\": " << Num(in.visible_background_jitter_px)
     << ", \"visible_background_jitter_out_px\": " << Num(out.visible_background_jitter_px)
     << ", \"line_deviation_px\": " << Num(out.line_deviation_px)
     << ", \"distortion\": " << Num(out.distortion)
     << ", \"min_cell_ratio\": " << Num(out.min_cell_ratio)
     << ", \"cropping\": " << Num(out.cropping)
     << ", \"undefined_fraction\": " << Num(out.undefined_fraction) << "}";
  return tj.str();
}

}  // namespace

namespace {

// What the report measures from the states alone: per-frame timings, the
// face's and the target's centres, the residual rotation, the face losses.
struct StateSeries {
  std::vector<double> face_ms, stab_ms, warp_ms, total_ms, solver_ms, iters;
  std::vector<Eigen::Vector2d> c_in, c_out, shake;
  // Frames without valid landmarks while a face was locked, by reason.
  std::map<std::string, int> face_losses;
  double fps = 30.0;  // of the data
};

StateSeries Series(const BagSink& sink) {
  StateSeries t;
  for (const auto& s : sink.states) {
    if (s.face_state == 2 /* LOST */) ++t.face_losses[s.face_failure];
    t.face_ms.push_back(s.face_ms);
    t.stab_ms.push_back(s.stabilizer_ms);
    t.warp_ms.push_back(s.warp_ms);
    t.total_ms.push_back(s.total_ms);
    t.solver_ms.push_back(s.solver_time_ms);
    t.iters.push_back(s.solver_iterations);
    // Residual camera shake: virtual rotation vector (what the viewer sees
    // of the camera's rotation).
    Eigen::Quaterniond q;
    steadiface_ros::ToEigen(s.virtual_rotation, &q);
    const Eigen::Vector3d v = steadiface::LogSO3(q);
    t.shake.emplace_back(v.x(), v.y());
    if (s.has_target) {
      t.c_in.emplace_back(s.centre_c[0], s.centre_c[1]);
      t.c_out.emplace_back(s.target_h[0], s.target_h[1]);
    }
  }
  if (sink.states.size() > 2) {
    t.fps = (sink.states.size() - 1) /
            std::max(1e-9, (sink.states.back().header.stamp -
                            sink.states.front().header.stamp)
                               .toSec());
  }
  return t;
}

// The gyro-vs-video check as of the last frame (and its warnings on
// stderr); empty without frames.
std::string CheckJson(const BagSink& sink) {
  if (sink.states.empty()) return std::string();
  const auto& s = sink.states.back();
  std::ostringstream cj;
  cj << ",\n  \"gyro_video_check\": {\"judged\": "
     << (s.check_judged ? "true" : "false")
     << ", \"motion_px\": " << s.check_motion_px
     << ", \"residual_px\": " << s.check_residual_px
     << ", \"best_mounting_residual_px\": "
     << s.check_best_mounting_residual_px
     << ", \"imu_rotation_contradicts\": "
     << (s.imu_rotation_contradicts ? "true" : "false")
     << ", \"suggested_R_cam_imu\": [" << s.suggested_R_cam_imu.x << ", "
     << s.suggested_R_cam_imu.y << ", " << s.suggested_R_cam_imu.z << ", "
     << s.suggested_R_cam_imu.w << "]"
     << ", \"imu_offset_correction_s\": " << s.imu_offset_correction_s
     << ", \"imu_offset_off\": " << (s.imu_offset_off ? "true" : "false")
     << ", \"imu_offset_applied_s\": " << s.imu_offset_applied_s << "}";
  if (s.imu_rotation_contradicts) {
    std::cerr << "steadiface_bag: WARNING: imu/R_cam_imu contradicts the "
                 "video (residual "
              << s.check_residual_px << " px; the axis permutation ["
              << s.suggested_R_cam_imu.x << ", " << s.suggested_R_cam_imu.y
              << ", " << s.suggested_R_cam_imu.z << ", "
              << s.suggested_R_cam_imu.w << "] explains it to "
              << s.check_best_mounting_residual_px
              << " px): set imu/R_cam_imu, and add "
              << s.imu_offset_correction_s * 1e3
              << " ms to imu/time_offset\n";
  } else if (s.imu_offset_off) {
    std::cerr << "steadiface_bag: WARNING: imu/time_offset is off by "
              << s.imu_offset_correction_s * 1e3
              << " ms (add it to imu/time_offset; "
              << s.imu_offset_applied_s * 1e3
              << " ms was applied by the last frame, "
                 "gyro_video_check/apply_offset)\n";
  }
  return cj.str();
}

// The wrapper's counters, from "dropped" to "face_lost_frames_by_reason".
void CountersJson(const steadiface_ros::WrapperStatus& ws, const StateSeries& t,
                  std::ostream& rep) {
  rep << ",\n  \"dropped\": {\"bad_image\": " << ws.counters.dropped_bad_image
      << ", \"bad_info\": " << ws.counters.dropped_bad_info
      << ", \"no_gyro\": " << ws.counters.dropped_no_gyro
      << ", \"queue_full\": " << ws.counters.dropped_queue_full
      << ", \"old_stamp\": " << ws.counters.dropped_old_stamp
      << ", \"refused\": " << ws.counters.dropped_pipeline_error << "}"
      << ",\n  \"passthrough_no_imu\": " << ws.counters.passthrough
      << ",\n  \"withheld_first_from_video\": " << ws.counters.withheld
      << ",\n  \"extrapolated\": " << ws.counters.extrapolated
      << ",\n  \"protrusion_searches\": " << ws.stabilizer.protrusion_searches
      << ",\n  \"previous_warp_fallbacks\": "
      << ws.stabilizer.previous_warp_fallbacks
      << ",\n  \"undefined_frames\": " << ws.stabilizer.undefined_frames
      << ",\n  \"solver_failures\": " << ws.stabilizer.solver_failures
      << ",\n  \"solver_restarts\": " << ws.stabilizer.solver_restarts
      << ",\n  \"frames_with_face\": " << ws.stabilizer.frames_with_face
      << ",\n  \"face_lost_frames_by_reason\": {";
  bool first_reason = true;
  for (const auto& kv : t.face_losses) {
    rep << (first_reason ? "" : ", ") << "\"" << kv.first << "\": " << kv.second;
    first_reason = false;
  }
  rep << "}";
}

void TimingsJson(const StateSeries& t, std::ostream& rep) {
  rep << ",\n  \"timings_ms\": {"
      << "\"face\": [" << Percentile(t.face_ms, 0.5) << ", "
      << Percentile(t.face_ms, 0.99) << "], "
      << "\"stabilizer\": [" << Percentile(t.stab_ms, 0.5) << ", "
      << Percentile(t.stab_ms, 0.99) << "], "
      << "\"solver\": [" << Percentile(t.solver_ms, 0.5) << ", "
      << Percentile(t.solver_ms, 0.99) << "], "
      << "\"warp\": [" << Percentile(t.warp_ms, 0.5) << ", "
      << Percentile(t.warp_ms, 0.99) << "], "
      << "\"total\": [" << Percentile(t.total_ms, 0.5) << ", "
      << Percentile(t.total_ms, 0.99) << "]}"
      << ",\n  \"solver_iterations_median\": " << Percentile(t.iters, 0.5);
}

}  // namespace

std::string MakeReport(const ReportInputs& r, const BagSink& sink,
                       const steadiface_ros::WrapperStatus& ws) {
  // Report: what can be measured without ground truth.
  const StateSeries t = Series(sink);
  const std::string truth_json = r.scorer ? TruthJson(r, sink) : std::string();
  const std::string check_json = CheckJson(sink);
  std::ostringstream rep;
  rep.precision(6);
  rep << "{\n  \"input\": \"" << r.in
      << "\",\n  \"frames_in\": " << ws.counters.images_in
      << ",\n  \"frames_out\": " << ws.counters.frames_out
      << ",\n  \"wall_time_s\": " << r.elapsed_s << ",\n  \"throughput_fps\": "
      << ws.counters.frames_out / std::max(r.elapsed_s, 1e-9)
      << ",\n  \"landmark_centre_jitter_in_norm\": "
      << HighPassRms(t.c_in, t.fps, 0.5) << ",\n  \"target_jitter_out_norm\": "
      << HighPassRms(t.c_out, t.fps, 0.5)
      << ",\n  \"residual_rotation_jitter_rad\": "
      << HighPassRms(t.shake, t.fps, 0.5)
      << ",\n  \"crop_ratio\": " << r.crop_ratio;
  CountersJson(ws, t, rep);
  TimingsJson(t, rep);
  rep << check_json << truth_json << ",\n  \"method\": \""
      << MethodName(r, sink) << "\"\n}\n";
  return rep.str();
}

void WriteTrajectory(const std::string& path, const BagSink& sink) {
  std::ofstream f(path);
  f.precision(17);
  f << "stamp,qx,qy,qz,qw,tx,ty,rqx,rqy,rqz,rqw,has_target,hx,hy,cx,cy,w_fit\n";
  for (const auto& s : sink.states) {
    f << s.header.stamp.toSec() << "," << s.virtual_rotation.x << ","
      << s.virtual_rotation.y << "," << s.virtual_rotation.z << ","
      << s.virtual_rotation.w << "," << s.principal_offset[0] << ","
      << s.principal_offset[1] << "," << s.real_rotation.x << ","
      << s.real_rotation.y << "," << s.real_rotation.z << ","
      << s.real_rotation.w << "," << static_cast<int>(s.has_target) << ","
      << s.target_h[0] << ","
      << s.target_h[1] << "," << s.centre_c[0] << "," << s.centre_c[1] << ","
      << s.w_fit << "\n";
  }
}

}  // namespace steadiface_bag

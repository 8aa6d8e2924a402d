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

// "gyro-only", "steadiface" or "steadiface-layered" (warp/mode layered).
std::string MethodName(const ReportInputs& r, const BagSink& sink) {
  if (r.gyro_only) return "gyro-only";
  const bool layered = !sink.states.empty() && sink.states.back().warp_mode == "layered";
  return layered ? "steadiface-layered" : "steadiface";
}

}  // namespace

std::string MakeReport(const ReportInputs& r, const BagSink& sink,
                       const steadiface_ros::WrapperStatus& ws) {
  // Report: what can be measured without ground truth.
  std::vector<double> face_ms, stab_ms, warp_ms, total_ms, solver_ms, iters;
  std::vector<Eigen::Vector2d> c_in, c_out, shake;
  // Frames without valid landmarks while a face was locked, by reason.
  std::map<std::string, int> face_losses;
  for (size_t i = 0; i < sink.states.size(); ++i) {
    const auto& s = sink.states[i];
    if (s.face_state == 2 /* LOST */) ++face_losses[s.face_failure];
    face_ms.push_back(s.face_ms);
    stab_ms.push_back(s.stabilizer_ms);
    warp_ms.push_back(s.warp_ms);
    total_ms.push_back(s.total_ms);
    solver_ms.push_back(s.solver_time_ms);
    iters.push_back(s.solver_iterations);
    // Residual camera shake: virtual rotation vector (what the viewer sees
    // of the camera's rotation).
    Eigen::Quaterniond q;
    steadiface_ros::ToEigen(s.virtual_rotation, &q);
    const Eigen::Vector3d v = steadiface::LogSO3(q);
    shake.emplace_back(v.x(), v.y());
    if (s.has_target) {
      c_in.emplace_back(s.centre_c[0], s.centre_c[1]);
      c_out.emplace_back(s.target_h[0], s.target_h[1]);
    }
  }
  double fps_data = 30.0;
  if (sink.states.size() > 2) {
    fps_data = (sink.states.size() - 1) /
               std::max(1e-9, (sink.states.back().header.stamp -
                               sink.states.front().header.stamp)
                                  .toSec());
  }
  // Ground truth (simulator bags): the true head centre and far-background
  // directions mapped through each frame's warp, as the scorecard does. The
  // warp of a frame is K_out R_v R_r^-1 K_in^-1 (middle-row R_r; the rolling
  // shutter's within-frame part is below a pixel here). In layered mode the
  // head is mapped through the subject layer and the background through the
  // background layer (the band and the slow whole-frame shift are not
  // modelled here; steadiface_evaluate scores the exact mesh).
  std::string truth_json;
  if (!r.truth.empty() && !sink.states.empty() && r.have_input_info) {
    std::ifstream tf(r.truth);
    std::string line;
    std::getline(tf, line);
    struct T {
      Eigen::Vector2d head;
      bool in_view;
      std::vector<Eigen::Quaterniond> rows;
    };
    std::map<int64_t, T> truth;  // by stamp in ms
    while (std::getline(tf, line)) {
      std::vector<double> v;
      std::stringstream ss(line);
      std::string cell;
      while (std::getline(ss, cell, ',')) v.push_back(std::atof(cell.c_str()));
      if (v.size() < 9 + 64) continue;
      T t;
      t.head = Eigen::Vector2d(v[2], v[3]);
      t.in_view = v[4] != 0;
      for (int r = 0; r < 16; ++r) {
        t.rows.emplace_back(v[9 + 4 * r + 3], v[9 + 4 * r], v[9 + 4 * r + 1],
                            v[9 + 4 * r + 2]);
      }
      truth[std::llround(v[1] * 1000.0)] = t;
    }
    const Eigen::Matrix3d K_in =
        (Eigen::Matrix3d() << r.input_info.K[0], 0, r.input_info.K[2], 0,
         r.input_info.K[4], r.input_info.K[5], 0, 0, 1)
            .finished();
    std::vector<Eigen::Vector2d> h_in, h_out, b_in, b_out;
    Eigen::Vector3d dir = Eigen::Vector3d::Zero();
    std::ofstream traj_none, traj_method;
    if (!r.plot_dir.empty()) {
      const std::string head =
          "t,head_in_x,head_in_y,head_out_x,head_out_y,head_valid,bg_out_x,bg_"
          "out_y,"
          "virt_rx,virt_ry,virt_rz,real_rx,real_ry,real_rz,tx,ty\n";
      traj_method.open(r.plot_dir + "/traj_" + r.plot_name + "_" +
                       MethodName(r, sink) + ".csv");
      traj_method << head;
      if (!r.gyro_only) {
        traj_none.open(r.plot_dir + "/traj_" + r.plot_name + "_none.csv");
        traj_none << head;
      }
    }
    const double t0 = sink.states.front().header.stamp.toSec();
    for (size_t i = 0; i < sink.states.size() && i < sink.infos_out.size();
         ++i) {
      const auto& s = sink.states[i];
      auto it = truth.find(std::llround(s.header.stamp.toSec() * 1000.0));
      if (it == truth.end()) continue;
      const T& t = it->second;
      Eigen::Quaterniond Rv, Rr;
      steadiface_ros::ToEigen(s.virtual_rotation, &Rv);
      steadiface_ros::ToEigen(s.real_rotation, &Rr);
      const auto& ko = sink.infos_out[i].K;
      const Eigen::Matrix3d K_out =
          (Eigen::Matrix3d() << ko[0], 0, ko[2], 0, ko[4], ko[5], 0, 0, 1)
              .finished();
      const bool layered = s.warp_mode == "layered" && s.has_background_layer;
      Eigen::Matrix3d H_head =
          K_out * (Rv * Rr.conjugate()).toRotationMatrix() * K_in.inverse();
      Eigen::Matrix3d H = H_head;
      if (layered) {
        // The published intrinsics are the background layer's; the subject
        // layer's differ by its principal offset (output px per unit of t:
        // fx_out / f_v, f_v = fx_in / W_in * virtual_focal_scale).
        Eigen::Quaterniond Rb;
        steadiface_ros::ToEigen(s.background_rotation, &Rb);
        const double f_v = r.input_info.K[0] / r.input_info.width * r.virtual_focal_scale;
        Eigen::Matrix3d K_s = K_out;
        K_s(0, 2) += ko[0] / f_v * (s.principal_offset[0] - s.background_principal_offset[0]);
        K_s(1, 2) += ko[4] / f_v * (s.principal_offset[1] - s.background_principal_offset[1]);
        H_head = K_s * (Rv * Rr.conjugate()).toRotationMatrix() * K_in.inverse();
        H = K_out * (Rb * Rr.conjugate()).toRotationMatrix() * K_in.inverse();
      }
      // A far-background direction fixed in the world: the first frame's
      // view centre, seen in each frame through the true middle-row rotation.
      const Eigen::Quaterniond R_true = t.rows[7];
      if (dir.isZero())
        dir = R_true.conjugate() * Eigen::Vector3d(0.05, 0.03, 1.0);
      const Eigen::Vector3d c = R_true * dir;
      const Eigen::Vector2d bin = (K_in * c).hnormalized();
      const Eigen::Vector2d bout = (H * bin.homogeneous()).hnormalized();
      b_in.push_back(bin);
      b_out.push_back(bout);
      Eigen::Vector2d hout = Eigen::Vector2d::Constant(NAN);
      if (t.in_view) {
        hout = (H_head * t.head.homogeneous()).hnormalized();
        h_in.push_back(t.head);
        h_out.push_back(hout);
      }
      const Eigen::Vector3d vr = steadiface::LogSO3(Rv),
                            rr = steadiface::LogSO3(Rr);
      auto row = [&](std::ofstream& f, const Eigen::Vector2d& ho,
                     const Eigen::Vector2d& bo, const Eigen::Vector3d& v,
                     const Eigen::Vector3d& r, double tx, double ty) {
        if (!f.is_open()) return;
        f << s.header.stamp.toSec() - t0 << "," << t.head.x() << ","
          << t.head.y() << "," << ho.x() << "," << ho.y() << "," << t.in_view
          << "," << bo.x() << "," << bo.y() << "," << v.x() << "," << v.y()
          << "," << v.z() << "," << r.x() << "," << r.y() << "," << r.z() << ","
          << tx << "," << ty << "\n";
      };
      row(traj_method, hout, bout, vr, rr, s.principal_offset[0],
          s.principal_offset[1]);
      row(traj_none, t.in_view ? t.head : Eigen::Vector2d::Constant(NAN), bin,
          rr, rr, 0.0, 0.0);
    }
    const double diag = std::hypot(r.input_info.width, r.input_info.height);
    std::ostringstream tj;
    tj << ",\n  \"ground_truth\": {\"truth\": \"" << r.truth << "\""
       << ", \"head_jitter_in_px\": " << HighPassRms(h_in, fps_data, 0.5)
       << ", \"head_jitter_out_px\": " << HighPassRms(h_out, fps_data, 0.5)
       << ", \"head_jitter_out_frac\": "
       << HighPassRms(h_out, fps_data, 0.5) / diag
       << ", \"background_jitter_in_px\": " << HighPassRms(b_in, fps_data, 0.5)
       << ", \"background_jitter_out_px\": "
       << HighPassRms(b_out, fps_data, 0.5)
       << ", \"cropping\": " << std::pow(1.0 - 2.0 * r.crop_ratio, 2.0)
       << ", \"undefined_fraction\": "
       << static_cast<double>(ws.stabilizer.undefined_frames) /
              std::max<size_t>(1, sink.states.size())
       << "}";
    truth_json = tj.str();
  }
  // The gyro-vs-video check as of the last frame.
  std::string check_json;
  if (!sink.states.empty()) {
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
    check_json = cj.str();
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
  }
  std::ostringstream rep;
  rep.precision(6);
  rep << "{\n  \"input\": \"" << r.in
      << "\",\n  \"frames_in\": " << ws.counters.images_in
      << ",\n  \"frames_out\": " << ws.counters.frames_out
      << ",\n  \"wall_time_s\": " << r.elapsed_s << ",\n  \"throughput_fps\": "
      << ws.counters.frames_out / std::max(r.elapsed_s, 1e-9)
      << ",\n  \"landmark_centre_jitter_in_norm\": "
      << HighPassRms(c_in, fps_data, 0.5) << ",\n  \"target_jitter_out_norm\": "
      << HighPassRms(c_out, fps_data, 0.5)
      << ",\n  \"residual_rotation_jitter_rad\": "
      << HighPassRms(shake, fps_data, 0.5)
      << ",\n  \"crop_ratio\": " << r.crop_ratio
      << ",\n  \"dropped\": {\"bad_image\": " << ws.counters.dropped_bad_image
      << ", \"bad_info\": " << ws.counters.dropped_bad_info
      << ", \"no_gyro\": " << ws.counters.dropped_no_gyro
      << ", \"queue_full\": " << ws.counters.dropped_queue_full
      << ", \"old_stamp\": " << ws.counters.dropped_old_stamp
      << ", \"refused\": " << ws.counters.dropped_pipeline_error << "}"
      << ",\n  \"passthrough_no_imu\": " << ws.counters.passthrough
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
  for (const auto& kv : face_losses) {
    rep << (first_reason ? "" : ", ") << "\"" << kv.first << "\": " << kv.second;
    first_reason = false;
  }
  rep << "}"
      << ",\n  \"timings_ms\": {"
      << "\"face\": [" << Percentile(face_ms, 0.5) << ", "
      << Percentile(face_ms, 0.99) << "], "
      << "\"stabilizer\": [" << Percentile(stab_ms, 0.5) << ", "
      << Percentile(stab_ms, 0.99) << "], "
      << "\"solver\": [" << Percentile(solver_ms, 0.5) << ", "
      << Percentile(solver_ms, 0.99) << "], "
      << "\"warp\": [" << Percentile(warp_ms, 0.5) << ", "
      << Percentile(warp_ms, 0.99) << "], "
      << "\"total\": [" << Percentile(total_ms, 0.5) << ", "
      << Percentile(total_ms, 0.99) << "]}"
      << ",\n  \"solver_iterations_median\": " << Percentile(iters, 0.5)
      << check_json << truth_json << ",\n  \"method\": \""
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

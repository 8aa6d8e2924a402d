#include "steadiface_core/eval/calibration_sweep.h"

#include <cmath>
#include <cstdio>
#include <memory>

#include <opencv2/imgproc.hpp>

#include "steadiface_core/check/gyro_video_check.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace eval {
namespace {

bool ParseFormat(const std::string& format, int* width, int* height) {
  return std::sscanf(format.c_str(), "%dx%d", width, height) == 2;
}

// The worst error of one kind and the recording it came from.
struct Worst {
  double value = 0.0;
  std::string at;
  void Add(double v, const std::string& where) {
    if (v > value) value = v, at = where;
  }
};

std::string Where(const SweepJob& j) {
  char at[96];
  std::snprintf(at, sizeof(at), "%s seed %d perm %d offset %.0f ms readout %.0f ms",
                j.format.c_str(), static_cast<int>(j.seed), j.permutation, j.offset_s * 1e3,
                j.readout_s * 1e3);
  return at;
}

}  // namespace

std::vector<SweepJob> SweepJobs(const CalibrationSweepOptions& o) {
  std::vector<int> perms = o.permutations;
  if (perms.empty()) {
    for (int i = 0; i < 24; ++i) perms.push_back(i);
  }
  std::vector<SweepJob> jobs;
  size_t cell = 0;
  for (const std::string& f : o.formats) {
    for (uint64_t seed : o.seeds) {
      for (int p : perms) {
        if (o.full) {
          for (double off : o.offsets) {
            for (double r : o.readouts) jobs.push_back({f, seed, p, off, r});
          }
        } else {
          const double off = o.offsets[cell % o.offsets.size()];
          const double r = o.readouts[(cell / o.offsets.size()) % o.readouts.size()];
          ++cell;
          jobs.push_back({f, seed, p, off, r});
        }
      }
    }
  }
  return jobs;
}

Status RunSweepJob(const CalibrationSweepOptions& o, const SweepJob& j, CalibrationResult* r,
                   Eigen::Quaterniond* mounting) {
  sim::SimulatorOptions so;
  so.data_dir = o.data_dir;
  Status st = sim::ApplyPreset("walk", &so);
  if (!st.ok()) return st;
  const bool mono = j.format.find("mono") != std::string::npos;
  if (!ParseFormat(j.format, &so.width, &so.height)) {
    return Status::Error("format '" + j.format + "' is not WxH[mono]");
  }
  so.duration_s = o.duration_s;
  so.readout_s = j.readout_s;
  so.imu_clock_offset_s = j.offset_s;
  so.seed = j.seed;
  std::unique_ptr<sim::Simulator> sim;
  st = sim::Simulator::Create(so, &sim);
  if (!st.ok()) return st;
  *mounting = (GyroVideoCheck::SignedAxisPermutations()[j.permutation] *
               Eigen::Quaterniond(Eigen::AngleAxisd(o.tilt_deg * M_PI / 180.0,
                                                    Eigen::Vector3d(1, 2, 3).normalized())))
                  .normalized();
  std::unique_ptr<Calibrator> cal;
  st = Calibrator::Create(sim->intrinsics(), RollingShutterOptions(),
                          Eigen::Quaterniond::Identity(), 0.0, CalibratorOptions(), &cal);
  if (!st.ok()) return st;
  for (GyroSample g : sim->imu()) {
    g.angular_velocity = mounting->conjugate() * g.angular_velocity;
    cal->AddGyro(g);
  }
  for (int i = 0; st.ok() && i < sim->num_frames(); ++i) {
    cv::Mat f;
    sim::SimTruth t;
    st = sim->Render(i, &f, &t);
    if (mono && st.ok()) cv::cvtColor(f, f, cv::COLOR_BGR2GRAY);
    if (st.ok()) st = cal->AddFrame(f, t.stamp);
  }
  if (st.ok()) st = cal->Solve(r);
  return st;
}

int RunCalibrationSweep(const CalibrationSweepOptions& o, std::ostream& out, std::ostream& err) {
  const std::vector<SweepJob> jobs = SweepJobs(o);
  for (const SweepJob& j : jobs) {
    int w, h;
    if (!ParseFormat(j.format, &w, &h)) {
      err << "steadiface_calibration_sweep: format '" << j.format << "' is not WxH[mono]\n";
      return 2;
    }
  }
  out << "| format | seed | permutation | offset ms | readout ms | offset err ms | "
         "readout err ms | rotation err deg | residual px | status |\n"
         "|---|---|---|---|---|---|---|---|---|---|\n";
  Worst worst_o, worst_r, worst_q;
  int failures = 0;
  for (const SweepJob& j : jobs) {
    CalibrationResult r;
    Eigen::Quaterniond mounting;
    const Status st = RunSweepJob(o, j, &r, &mounting);
    if (!st.ok()) {
      ++failures;
      out << "| " << j.format << " | " << j.seed << " | " << j.permutation << " | "
          << j.offset_s * 1e3 << " | " << j.readout_s * 1e3
          << " | – | – | – | – | refused: " << st.message() << " |" << std::endl;
      continue;
    }
    const double eo = (r.time_offset_s - j.offset_s) * 1e3, er = (r.readout_s - j.readout_s) * 1e3;
    const double eq = r.R_cam_imu.angularDistance(mounting) * 180.0 / M_PI;
    worst_o.Add(std::abs(eo), Where(j));
    worst_r.Add(std::abs(er), Where(j));
    worst_q.Add(eq, Where(j));
    char row[256];
    std::snprintf(row, sizeof(row), "| %s | %d | %d | %.0f | %.0f | %+.3f | %+.3f | %.3f | %.3f | ok |",
                  j.format.c_str(), static_cast<int>(j.seed), j.permutation, j.offset_s * 1e3,
                  j.readout_s * 1e3, eo, er, eq, r.residual_after_px);
    out << row << std::endl;
  }
  char summary[512];
  std::snprintf(summary, sizeof(summary),
                "\n%zu recordings, %d refused; worst offset error %.3f ms (%s), readout %.3f ms "
                "(%s), rotation %.3f deg (%s)\n",
                jobs.size(), failures, worst_o.value, worst_o.at.c_str(), worst_r.value,
                worst_r.at.c_str(), worst_q.value, worst_q.at.c_str());
  out << summary;
  return failures == 0 ? 0 : 1;
}

}  // namespace eval
}  // namespace steadiface

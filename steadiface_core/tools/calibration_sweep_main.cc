// steadiface_calibration_sweep: the offline calibration (issue 16) on
// simulated recordings with known truth, over a grid of clock offsets,
// readouts, IMU mountings (the 24 signed axis permutations, each tilted by
// a misalignment), seeds and camera formats; prints one markdown row per
// recording and the worst errors. The gyro carries the simulator's noise
// and constant bias.
//   steadiface_calibration_sweep --data DIR [--offsets
//   -0.04,-0.015,0,0.012,0.035]
//       [--readouts 0,0.01,0.025,0.033] [--permutations all|N,M] [--seeds
//       1,2,3]
//       [--formats 640x360,752x480mono] [--duration S] [--tilt DEG]
// By default each permutation is paired with one offset x readout cell in
// turn (cycling), so every permutation, offset and readout appears; --full
// runs the whole product.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "steadiface_core/calibration/calibrator.h"
#include "steadiface_core/check/gyro_video_check.h"
#include "steadiface_core/common/command_line.h"
#include "steadiface_core/sim/simulator.h"

namespace {

std::vector<double> Numbers(const std::string& s) {
  std::vector<double> out;
  std::stringstream ss(s);
  std::string x;
  while (std::getline(ss, x, ',')) out.push_back(std::atof(x.c_str()));
  return out;
}

std::vector<std::string> Words(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string x;
  while (std::getline(ss, x, ',')) out.push_back(x);
  return out;
}

int Usage() {
  std::cerr << "usage: steadiface_calibration_sweep --data DIR [--offsets a,b] "
               "[--readouts a,b]\n"
               "  [--permutations all|i,j] [--seeds 1,2,3] [--formats "
               "640x360,752x480mono]\n"
               "  [--duration S] [--tilt DEG] [--full]\n";
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace steadiface;  // NOLINT: a tool's main
  std::string data;
  std::vector<double> offsets = {-0.04, -0.015, 0.0, 0.012, 0.035};
  std::vector<double> readouts = {0.0, 0.01, 0.025, 0.033};
  std::vector<double> seeds = {1, 2, 3};
  std::vector<std::string> formats = {"640x360", "752x480mono"};
  std::vector<int> perms;
  for (int i = 0; i < 24; ++i) perms.push_back(i);
  double duration = 3.0, tilt_deg = 2.0;
  bool full = false;
  CommandLine cl;
  cl.String("--data", &data).Double("--duration", &duration).Double("--tilt", &tilt_deg);
  cl.Flag("--full", &full);
  cl.Value("--offsets", "numbers", [&](const std::string& v) { return !(offsets = Numbers(v)).empty(); });
  cl.Value("--readouts", "numbers", [&](const std::string& v) { return !(readouts = Numbers(v)).empty(); });
  cl.Value("--seeds", "numbers", [&](const std::string& v) { return !(seeds = Numbers(v)).empty(); });
  cl.Value("--formats", "words", [&](const std::string& v) { return !(formats = Words(v)).empty(); });
  cl.Value("--permutations", "'all' or numbers", [&](const std::string& p) {
    if (p == "all") return true;
    perms.clear();
    for (double v : Numbers(p)) perms.push_back(static_cast<int>(v));
    return !perms.empty();
  });
  std::string error;
  const CommandLine::Result parsed = cl.Parse(argc, argv, &error);
  if (parsed == CommandLine::Result::kHelp) {
    Usage();
    return 0;
  }
  if (parsed == CommandLine::Result::kError) {
    std::cerr << "steadiface_calibration_sweep: " << error << "\n";
    return Usage();
  }
  if (data.empty() || offsets.empty() || readouts.empty() || seeds.empty() ||
      formats.empty() || perms.empty()) {
    return Usage();
  }
  struct Job {
    std::string format;
    uint64_t seed;
    int perm;
    double offset, readout;
  };
  std::vector<Job> jobs;
  size_t cell = 0;
  for (const std::string& f : formats) {
    for (double seed : seeds) {
      for (int p : perms) {
        if (full) {
          for (double o : offsets) {
            for (double r : readouts)
              jobs.push_back({f, static_cast<uint64_t>(seed), p, o, r});
          }
        } else {
          const double o = offsets[cell % offsets.size()];
          const double r = readouts[(cell / offsets.size()) % readouts.size()];
          ++cell;
          jobs.push_back({f, static_cast<uint64_t>(seed), p, o, r});
        }
      }
    }
  }
  std::cout << "| format | seed | permutation | offset ms | readout ms | "
               "offset err ms | "
               "readout err ms | rotation err deg | residual px | status |\n"
               "|---|---|---|---|---|---|---|---|---|---|\n";
  double worst_o = 0, worst_r = 0, worst_q = 0;
  std::string worst_o_at, worst_r_at, worst_q_at;
  int failures = 0;
  for (const Job& j : jobs) {
    sim::SimulatorOptions so;
    so.data_dir = data;
    sim::ApplyPreset("walk", &so);
    const bool mono = j.format.find("mono") != std::string::npos;
    if (std::sscanf(j.format.c_str(), "%dx%d", &so.width, &so.height) != 2)
      return Usage();
    so.duration_s = duration;
    so.readout_s = j.readout;
    so.imu_clock_offset_s = j.offset;
    so.seed = j.seed;
    std::unique_ptr<sim::Simulator> sim;
    Status st = sim::Simulator::Create(so, &sim);
    if (!st.ok()) {
      std::cerr << st.message() << "\n";
      return 1;
    }
    const Eigen::Quaterniond mounting =
        (GyroVideoCheck::SignedAxisPermutations()[j.perm] *
         Eigen::Quaterniond(Eigen::AngleAxisd(
             tilt_deg * M_PI / 180.0, Eigen::Vector3d(1, 2, 3).normalized())))
            .normalized();
    std::unique_ptr<Calibrator> cal;
    st = Calibrator::Create(sim->intrinsics(), RollingShutterOptions(),
                            Eigen::Quaterniond::Identity(), 0.0,
                            CalibratorOptions(), &cal);
    for (GyroSample g : sim->imu()) {
      g.angular_velocity = mounting.conjugate() * g.angular_velocity;
      cal->AddGyro(g);
    }
    for (int i = 0; st.ok() && i < sim->num_frames(); ++i) {
      cv::Mat f;
      sim::SimTruth t;
      st = sim->Render(i, &f, &t);
      if (mono && st.ok()) cv::cvtColor(f, f, cv::COLOR_BGR2GRAY);
      if (st.ok()) st = cal->AddFrame(f, t.stamp);
    }
    CalibrationResult r;
    if (st.ok()) st = cal->Solve(&r);
    const double eo = (r.time_offset_s - j.offset) * 1e3,
                 er = (r.readout_s - j.readout) * 1e3;
    const double eq = r.R_cam_imu.angularDistance(mounting) * 180.0 / M_PI;
    char at[96];
    std::snprintf(at, sizeof(at),
                  "%s seed %d perm %d offset %.0f ms readout %.0f ms",
                  j.format.c_str(), static_cast<int>(j.seed), j.perm,
                  j.offset * 1e3, j.readout * 1e3);
    if (!st.ok()) {
      ++failures;
      std::cout << "| " << j.format << " | " << j.seed << " | " << j.perm
                << " | " << j.offset * 1e3 << " | " << j.readout * 1e3
                << " | – | – | – | – | refused: " << st.message() << " |"
                << std::endl;
      continue;
    }
    if (std::abs(eo) > worst_o) worst_o = std::abs(eo), worst_o_at = at;
    if (std::abs(er) > worst_r) worst_r = std::abs(er), worst_r_at = at;
    if (eq > worst_q) worst_q = eq, worst_q_at = at;
    char row[256];
    std::snprintf(
        row, sizeof(row),
        "| %s | %d | %d | %.0f | %.0f | %+.3f | %+.3f | %.3f | %.3f | ok |",
        j.format.c_str(), static_cast<int>(j.seed), j.perm, j.offset * 1e3,
        j.readout * 1e3, eo, er, eq, r.residual_after_px);
    std::cout << row << std::endl;
  }
  std::printf(
      "\n%zu recordings, %d refused; worst offset error %.3f ms (%s), readout "
      "%.3f ms "
      "(%s), rotation %.3f deg (%s)\n",
      jobs.size(), failures, worst_o, worst_o_at.c_str(), worst_r,
      worst_r_at.c_str(), worst_q, worst_q_at.c_str());
  return failures == 0 ? 0 : 1;
}

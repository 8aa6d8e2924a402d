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
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "steadiface_core/common/command_line.h"
#include "steadiface_core/eval/calibration_sweep.h"

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

const char kUsage[] =
    "usage: steadiface_calibration_sweep --data DIR [--offsets a,b] [--readouts a,b]\n"
    "  [--permutations all|i,j] [--seeds 1,2,3] [--formats 640x360,752x480mono]\n"
    "  [--duration S] [--tilt DEG] [--full]\n";

void AddFlags(steadiface::CommandLine* cl, steadiface::eval::CalibrationSweepOptions* o) {
  cl->String("--data", &o->data_dir).Double("--duration", &o->duration_s);
  cl->Double("--tilt", &o->tilt_deg).Flag("--full", &o->full);
  cl->Value("--offsets", "numbers",
            [o](const std::string& v) { return !(o->offsets = Numbers(v)).empty(); });
  cl->Value("--readouts", "numbers",
            [o](const std::string& v) { return !(o->readouts = Numbers(v)).empty(); });
  cl->Value("--seeds", "numbers", [o](const std::string& v) {
    o->seeds.clear();
    for (double x : Numbers(v)) o->seeds.push_back(static_cast<uint64_t>(x));
    return !o->seeds.empty();
  });
  cl->Value("--formats", "words",
            [o](const std::string& v) { return !(o->formats = Words(v)).empty(); });
  cl->Value("--permutations", "'all' or numbers", [o](const std::string& p) {
    o->permutations.clear();
    if (p == "all") return true;
    for (double v : Numbers(p)) o->permutations.push_back(static_cast<int>(v));
    return !o->permutations.empty();
  });
}

}  // namespace

int main(int argc, char** argv) {
  steadiface::eval::CalibrationSweepOptions o;
  steadiface::CommandLine cl;
  AddFlags(&cl, &o);
  int status = 0;
  if (!cl.Start(argc, argv, "steadiface_calibration_sweep", kUsage,
                [&o] { return !o.data_dir.empty(); }, std::cout, std::cerr, &status)) {
    return status;
  }
  return steadiface::eval::RunCalibrationSweep(o, std::cout, std::cerr);
}

#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

#include "steadiface_core/calibration/calibrator.h"
#include "steadiface_core/common/status.h"

namespace steadiface {
namespace eval {

/// The offline calibration's sweep over simulated recordings with known
/// truth (steadiface_calibration_sweep): a grid of clock offsets, readouts,
/// IMU mountings (the 24 signed axis permutations, each tilted by a
/// misalignment), seeds and camera formats. The gyro carries the
/// simulator's noise and constant bias.
struct CalibrationSweepOptions {
  std::string data_dir;  ///< the simulator's photos and gyro logs
  std::vector<double> offsets = {-0.04, -0.015, 0.0, 0.012, 0.035};  ///< IMU clock [s]
  std::vector<double> readouts = {0.0, 0.01, 0.025, 0.033};          ///< [s]
  std::vector<uint64_t> seeds = {1, 2, 3};
  /// WxH, with "mono" for grey images.
  std::vector<std::string> formats = {"640x360", "752x480mono"};
  /// Indices into GyroVideoCheck::SignedAxisPermutations(); default: all 24.
  std::vector<int> permutations;
  double duration_s = 3.0;  ///< each recording's length [s]
  double tilt_deg = 2.0;    ///< the misalignment added to each permutation [deg]
  /// false: each permutation takes one offset x readout cell in turn
  /// (cycling), so every permutation, offset and readout appears; true: the
  /// whole product.
  bool full = false;
};

/// One simulated recording of the sweep.
struct SweepJob {
  std::string format;
  uint64_t seed = 1;
  int permutation = 0;
  double offset_s = 0.0, readout_s = 0.0;
};

/// The recordings the options ask for, in order.
std::vector<SweepJob> SweepJobs(const CalibrationSweepOptions& options);

/// Simulates a walk as `job` says, calibrates it from nothing configured,
/// and gives the result with the true mounting.
Status RunSweepJob(const CalibrationSweepOptions& options, const SweepJob& job,
                   CalibrationResult* result, Eigen::Quaterniond* mounting);

/// Runs every job: one markdown row per recording to `out` and the worst
/// errors. Returns the process's exit status: 0 all calibrated, 1 some
/// refused or a recording could not be made, 2 a bad format.
int RunCalibrationSweep(const CalibrationSweepOptions& options, std::ostream& out,
                        std::ostream& err);

}  // namespace eval
}  // namespace steadiface

#pragma once

#include <string>
#include <vector>

#include "steadiface_bag/bag_reader.h"

namespace steadiface_calibrate {

/// What steadiface_calibrate runs (its command line).
struct CalibrateOptions {
  std::string in;      ///< the recording (a bag)
  std::string out;     ///< the parameter overlay to write
  std::string report;  ///< a JSON report (empty: none)
  std::string plot;    ///< a folder for angular_speed.{csv,png} (empty: none)
  /// Parameter files over config/default.yaml: the starting point
  /// (camera/stamp, camera/readout_time, imu/time_offset, camera_info_url).
  std::vector<std::string> params;
  steadiface_bag::BagTopics topics;
  bool estimate_readout = true;  ///< false: keep camera/readout_time
  bool quiet = false;            ///< no progress
};

/// The camera-IMU calibration from a recording with a few seconds of hand
/// shake: reads the bag, feeds steadiface::Calibrator, and writes the IMU
/// rotation, clock offset, gyro bias and (where determined) the readout as
/// an overlay that stabilize.launch (params:=) and steadiface_bag
/// (--params) load as is; with `report` and `plot` also those. Messages go
/// to stderr, the summary line to stdout. Returns the process's exit status:
/// 0 with the overlay written, 1 when the recording cannot determine the
/// result (the reason is printed; nothing is written). A recording without
/// IMU messages gives the rolling-shutter readout from the video alone
/// (steadiface::VideoReadoutEstimator), written as camera/readout_time.
int RunCalibration(const CalibrateOptions& options);

}  // namespace steadiface_calibrate

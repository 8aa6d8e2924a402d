#pragma once

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "steadiface_core/common/status.h"
#include "steadiface_core/sim/simulator.h"

namespace steadiface {
namespace sim {

/// How a simulated recording was made: the preset and what was set on top
/// of it, enough to rebuild its Simulator exactly (steadiface_simulate's
/// options).
struct SimulationSettings {
  std::string preset = "walk";
  /// Folder of the photos and gyro traces (absolute in a truth file).
  std::string data_dir;
  /// Image size [px], frame rate [Hz], duration [s], horizontal FOV [rad],
  /// IMU rate [Hz], seed, background photo, whether a face is rendered and
  /// the IMU clock's offset [s]: set before the preset is applied, as
  /// SimulatorOptions' fields of the same names; the duration is restored
  /// after it.
  SimulatorOptions base;
  /// The rolling shutter's readout [s]; < 0 keeps the preset's.
  double readout_s = -1.0;
  /// Recorded stamps are the simulator's plus this [s].
  double epoch_s = 0.0;
};

/// The preset with the settings on top, as steadiface_simulate applies them
/// (a preset that needs a longer sequence, dropout, keeps its length).
Status MakeSimulatorOptions(const SimulationSettings& settings, SimulatorOptions* options);

/// One frame of a truth file: the simulator's truth at the recorded stamp.
struct TruthRow {
  int frame = 0;
  double stamp_s = 0.0;  ///< recorded stamp (simulator's + epoch) [s]
  SimTruth truth;        ///< head, events and the 16 rows' true rotations
};

/// The ground-truth sidecar of a simulated bag (BAG.truth.csv), the one
/// format the simulator writes and the bag tool and the rostests read:
///   # steadiface truth v1 preset=walk data=/abs/dir width=640 ... epoch=1.7e9
///   frame,stamp,head_x,head_y,head_in_view,face_scale_px,occluded,face_out,
///   second_face,row0_qx,row0_qy,row0_qz,row0_qw,...,row15_qw
///   one line per frame (full precision).
/// A reader that only wants the columns skips lines that start with '#'.
class TruthFileWriter {
 public:
  /// Writes the settings line and the column names.
  TruthFileWriter(std::ostream* out, const SimulationSettings& settings);
  void Add(int frame, double stamp_s, const SimTruth& truth);

 private:
  std::ostream* out_;
};

/// Reads a truth file: the settings (when the file has them) and the rows.
Status ReadTruthFile(const std::string& path, SimulationSettings* settings, bool* has_settings,
                     std::vector<TruthRow>* rows);

/// The frame index of each row by its stamp in ms (rounded).
std::map<int64_t, int> FramesByStampMs(const std::vector<TruthRow>& rows);

}  // namespace sim
}  // namespace steadiface

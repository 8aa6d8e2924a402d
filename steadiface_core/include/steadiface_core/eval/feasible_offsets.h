#pragma once

#include <vector>

#include "steadiface_core/camera/camera_model.h"
#include "steadiface_core/common/status.h"
#include "steadiface_core/gyro/row_rotations.h"
#include "steadiface_core/camera/output_geometry.h"
#include "steadiface_core/warp/protrusion.h"

namespace steadiface {
namespace eval {

/// What the crop margin allows on one frame, whatever the stabilizer: the
/// principal offsets t for which the output is defined when the virtual
/// camera keeps the real rotation (R_v = R_r at the middle row), each
/// boundary sample with its own row's rotation (rolling shutter, as
/// ProtrusionGeometry checks it). A pure image shift of the crop window, so
/// it is what a shift-only policy can use (scripts/analysis/crop_bound.py --feasible);
/// a virtual camera that also rotates can reach other poses.
///
/// The set is given in polar form: for `directions` evenly spaced angles
/// (0 = +x, counter-clockwise in image coordinates, i.e. towards +y first)
/// the largest |t| along that ray with a defined output [input px], found by
/// bisection to `tolerance_px`. The set contains t = 0 (the real pose) when
/// the crop fits at all; a frame where even that protrudes gives all 0.
class FeasibleOffsets {
 public:
  FeasibleOffsets(const CameraModel& model, const OutputGeometry& output,
                  int samples_per_edge);

  /// Radii for one frame's rows (`middle` = the virtual rotation at t = 0:
  /// the rows' middle rotation, or Rolled() of it).
  std::vector<double> Radii(const RowRotations& rows, const Eigen::Quaterniond& middle,
                            int directions, double tolerance_px = 0.05) const;

  /// The virtual rotation that keeps the real one but rolls by `roll` [rad]
  /// about the optical axis: R_v = Rz(roll) R_r (R_v world -> virtual).
  /// With it Radii() gives the set of a window that also rolls: an upper
  /// bound on what the virtual camera's third freedom adds to a shift
  /// (scripts/analysis/crop_bound.py --feasible-roll).
  static Eigen::Quaterniond Rolled(const Eigen::Quaterniond& middle,
                                   double roll);

  /// Where the real pixel `pixel` (read at its own row) moves in the view
  /// when the virtual camera rolls by `roll` [rad] instead of keeping the
  /// real rotation, both at t = 0 [input px]. False when the point cannot be
  /// projected.
  bool RollShift(const RowRotations& rows, const Eigen::Quaterniond& middle,
                 double roll, const Eigen::Vector2d& pixel,
                 Eigen::Vector2d* shift) const;

 private:
  ProtrusionGeometry geometry_;
};

}  // namespace eval
}  // namespace steadiface

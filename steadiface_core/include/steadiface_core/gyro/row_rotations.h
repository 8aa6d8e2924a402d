#pragma once

#include <vector>

#include <Eigen/Geometry>

#include "steadiface_core/camera/rolling_shutter.h"
#include "steadiface_core/gyro/orientation_timeline.h"

namespace steadiface {

/// R_r(y) for one frame: the real rotation (world -> camera) of every image
/// row, tabulated at `samples` evenly spaced rows and slerped in between.
/// With a global shutter (or samples == 1) every row has the same rotation.
/// This is the one per-frame description of the real camera that the
/// stabilizer's protrusion term, the protrusion check and the warp share.
class RowRotations {
 public:
  RowRotations() = default;
  /// Every row shares R_r.
  explicit RowRotations(const Eigen::Quaterniond& R_r, int height = 1);

  /// Tabulates R_r(y) from the timeline. Fails (returns the failing query
  /// result) when the timeline cannot answer for some row; extrapolation
  /// within the timeline's allowance counts as success.
  static QueryResult Build(const OrientationTimeline& timeline,
                           const RowTiming& timing, Time stamp, int samples,
                           RowRotations* out);

  /// From rotations at `table.size()` evenly spaced rows 0 .. height-1.
  static RowRotations FromTable(std::vector<Eigen::Quaterniond> table,
                                int height);

  /// R_r at (fractional) pixel row y, clamped to [0, H-1]; a non-finite y
  /// gives the middle row.
  Eigen::Quaterniond At(double y) const;
  /// R_r at the middle row.
  Eigen::Quaterniond Middle() const { return At(0.5 * (height_ - 1)); }

  int height() const { return height_; }
  int samples() const { return static_cast<int>(table_.size()); }
  bool empty() const { return table_.empty(); }

 private:
  int height_ = 1;
  std::vector<Eigen::Quaterniond> table_;
};

/// R_r(y): the paper's real rotation (world -> camera) for row y of the frame
/// stamped `stamp`.
QueryResult RealRotationAtRow(const OrientationTimeline& timeline,
                              const RowTiming& timing, Time stamp, double y,
                              Eigen::Quaterniond* R_r);

}  // namespace steadiface

#pragma once

#include "steadiface_core/common/status.h"
#include "steadiface_core/common/time.h"

namespace steadiface {

/// Which instant an image's header stamp marks.
enum class StampConvention {
  kFirstRow,   ///< the first (top) row's capture time (start of readout)
  kMiddleRow,  ///< the middle row's capture time (mid-frame, e.g. Android)
  kLastRow,    ///< the last (bottom) row's capture time (end of readout)
};

/// Rolling-shutter timing of the real camera.
struct RollingShutterOptions {
  /// Time from the top row's capture to the bottom row's capture [s].
  /// 0 for a global shutter. Typical phones: 10-33 ms.
  double readout_time_s = 0.0;
  /// What the image stamp marks.
  StampConvention stamp = StampConvention::kFirstRow;
  /// Added to every row time [s], e.g. +exposure/2 when stamps mark the start
  /// of exposure and rows should be taken at mid-exposure.
  double row_time_offset_s = 0.0;
};

Status ValidateRollingShutterOptions(const RollingShutterOptions& options);

/// The share of the readout from the top row to the stamped row: 0, 0.5 and
/// 1 for first-, middle- and last-row stamps (the s of RowTiming).
double StampShare(StampConvention stamp);

/// Capture time of every image row. Row y (pixel row, 0 = top, fractional
/// allowed) is captured at
///   t(y) = t_top + readout_time * y / (H - 1) + row_time_offset
/// where t_top = stamp - s * readout_time and s = 0, 0.5, 1 for first, middle
/// and last-row stamps. The top row is captured at t_top and the bottom row
/// at t_top + readout_time.
class RowTiming {
 public:
  /// `options` must be valid; `height` > 0.
  RowTiming(const RollingShutterOptions& options, int height);

  /// Capture time of (fractional) row y of the frame stamped `stamp`.
  Time RowTime(Time stamp, double y) const;
  /// Capture time of the top row.
  Time FirstRowTime(Time stamp) const { return RowTime(stamp, 0.0); }
  /// Capture time of the bottom row: gyro must cover this before the frame
  /// can be processed.
  Time LastRowTime(Time stamp) const { return RowTime(stamp, height_ - 1); }

  int height() const { return height_; }

 private:
  RollingShutterOptions options_;
  int height_;
};

}  // namespace steadiface

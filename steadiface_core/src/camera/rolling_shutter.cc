#include "steadiface_core/camera/rolling_shutter.h"

#include <cmath>
#include <sstream>

namespace steadiface {

Status ValidateRollingShutterOptions(const RollingShutterOptions& o) {
  std::ostringstream err;
  if (!std::isfinite(o.readout_time_s) || o.readout_time_s < 0.0 ||
      o.readout_time_s > 0.2) {
    err << "camera.readout_time must be in [0, 0.2] s, got "
        << o.readout_time_s;
  } else if (!std::isfinite(o.row_time_offset_s) ||
             std::abs(o.row_time_offset_s) > 0.5) {
    err << "camera.row_time_offset must be in [-0.5, 0.5] s, got "
        << o.row_time_offset_s;
  }
  if (err.tellp() != 0) return Status::Error(err.str());
  return Status::Ok();
}

RowTiming::RowTiming(const RollingShutterOptions& options, int height)
    : options_(options), height_(height < 1 ? 1 : height) {}

double StampShare(StampConvention stamp) {
  switch (stamp) {
    case StampConvention::kFirstRow:
      return 0.0;
    case StampConvention::kMiddleRow:
      return 0.5;
    case StampConvention::kLastRow:
      return 1.0;
  }
  return 0.0;
}

Time RowTiming::RowTime(Time stamp, double y) const {
  const double s = StampShare(options_.stamp);
  const double frac = height_ > 1 ? y / (height_ - 1) : 0.0;
  const double offset_s =
      options_.readout_time_s * (frac - s) + options_.row_time_offset_s;
  return stamp + FromSeconds(offset_s);
}

}  // namespace steadiface

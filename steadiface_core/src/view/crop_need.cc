#include "steadiface_core/view/crop_need.h"

#include "steadiface_core/warp/protrusion.h"

namespace steadiface {

double CropNeed(const CameraModel& model, const OutputGeometry& output,
                const Eigen::Quaterniond& R_v, const Eigen::Vector2d& t,
                const RowRotations& rows, int samples_per_edge, int steps) {
  auto defined_at = [&](double r) {
    const ProtrusionGeometry window(model, output.WithCropRatio(r),
                                    samples_per_edge);
    return window.Check(R_v, t, rows, 0.0).defined;
  };
  double lo = 0.0, hi = 0.4;  // hi: defined (or the narrowest window)
  if (!defined_at(hi)) return hi;
  if (defined_at(lo)) return lo;
  for (int i = 0; i < steps; ++i) {
    const double mid = 0.5 * (lo + hi);
    (defined_at(mid) ? hi : lo) = mid;
  }
  return hi;
}

}  // namespace steadiface

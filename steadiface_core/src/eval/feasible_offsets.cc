#include "steadiface_core/eval/feasible_offsets.h"

#include <cmath>

namespace steadiface {
namespace eval {

FeasibleOffsets::FeasibleOffsets(const CameraModel& model, const OutputGeometry& output,
                                 int samples_per_edge)
    : geometry_(model, output, samples_per_edge) {}

std::vector<double> FeasibleOffsets::Radii(const RowRotations& rows,
                                           const Eigen::Quaterniond& middle, int directions,
                                           double tolerance_px) const {
  const double width = geometry_.model().intrinsics().width;
  std::vector<double> radii(directions > 0 ? directions : 0, 0.0);
  if (!geometry_.Check(middle, Eigen::Vector2d::Zero(), rows, 0.0).defined) return radii;
  for (int k = 0; k < directions; ++k) {
    const double angle = 2.0 * M_PI * k / directions;
    const Eigen::Vector2d dir(std::cos(angle), std::sin(angle));
    // t in normalized units (fraction of the width): the whole frame bounds it.
    double lo = 0.0, hi = 1.0;
    while ((hi - lo) * width > tolerance_px) {
      const double mid = 0.5 * (lo + hi);
      (geometry_.Check(middle, mid * dir, rows, 0.0).defined ? lo : hi) = mid;
    }
    radii[k] = lo * width;
  }
  return radii;
}

}  // namespace eval
}  // namespace steadiface

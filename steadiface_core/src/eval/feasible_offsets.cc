#include "steadiface_core/eval/feasible_offsets.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

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

Eigen::Quaterniond FeasibleOffsets::Rolled(const Eigen::Quaterniond& middle,
                                           double roll) {
  return (Eigen::Quaterniond(
              Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitZ())) *
          middle)
      .normalized();
}

bool FeasibleOffsets::RollShift(const RowRotations& rows,
                                const Eigen::Quaterniond& middle, double roll,
                                const Eigen::Vector2d& pixel,
                                Eigen::Vector2d* shift) const {
  const CameraModel& model = geometry_.model();
  const int last_row = model.intrinsics().height - 1;
  const Eigen::Quaterniond R_row =
      rows.At(std::max(0.0, std::min<double>(last_row, pixel.y())));
  const Eigen::Vector2d L = model.PixelToNormalized(pixel);
  Eigen::Vector2d rolled, kept;
  if (!model.Project(L, Rolled(middle, roll), Eigen::Vector2d::Zero(), R_row,
                     &rolled) ||
      !model.Project(L, middle, Eigen::Vector2d::Zero(), R_row, &kept)) {
    return false;
  }
  // Normalized units are fractions of the width, in the virtual camera's
  // scale; input px at f_v / f_r = 1 (the output's zoom is the crop's).
  *shift = (rolled - kept) * model.intrinsics().width * model.real_focal() /
           model.virtual_focal();
  return shift->allFinite();
}

}  // namespace eval
}  // namespace steadiface

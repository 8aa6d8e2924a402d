#include "steadiface_core/warp/protrusion.h"

#include <algorithm>

namespace steadiface {

ProtrusionGeometry::ProtrusionGeometry(const CameraModel& model,
                                       const OutputGeometry& output,
                                       int samples_per_edge)
    : model_(model), boundary_(WindowBoundary(output, samples_per_edge)) {}

std::vector<Eigen::Vector2d> ProtrusionGeometry::WindowBoundary(const OutputGeometry& output,
                                                                int samples_per_edge) {
  const int n = std::max(2, samples_per_edge);
  const double w1 = output.width() - 1, h1 = output.height() - 1;
  std::vector<Eigen::Vector2d> boundary;
  boundary.reserve(4 * n);
  // Clockwise around the outer pixel centres, corners once.
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / n;
    boundary.push_back(output.OutputPixelToVirtual({s * w1, 0.0}));
  }
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / n;
    boundary.push_back(output.OutputPixelToVirtual({w1, s * h1}));
  }
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / n;
    boundary.push_back(output.OutputPixelToVirtual({w1 - s * w1, h1}));
  }
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / n;
    boundary.push_back(output.OutputPixelToVirtual({0.0, h1 - s * h1}));
  }
  return boundary;
}

ProtrusionReport ProtrusionGeometry::Check(const Eigen::Quaterniond& R_v,
                                           const Eigen::Vector2d& t,
                                           const RowRotations& rows,
                                           double shrink_px) const {
  ProtrusionReport report;
  report.rows.resize(boundary_.size());
  const CameraIntrinsics& k = model_.intrinsics();
  double worst = 0.0;
  bool all_finite = true;
  double row = 0.5 * (k.height - 1);
  for (size_t i = 0; i < boundary_.size(); ++i) {
    Eigen::Vector2d p;
    if (!VirtualToRealPixelRS(model_, R_v, t, rows, boundary_[i], 6, 1e-3, &p,
                              &row)) {
      all_finite = false;
      report.rows[i] = 0.5 * (k.height - 1);
      row = report.rows[i];
      continue;
    }
    report.rows[i] = row;
    const Eigen::Vector2d o = Outside<double>(p, k.width, k.height, shrink_px);
    worst = std::max(worst, o.norm());
  }
  report.defined = all_finite && worst == 0.0;
  report.max_outside_px =
      all_finite ? worst : std::numeric_limits<double>::infinity();
  return report;
}

}  // namespace steadiface
